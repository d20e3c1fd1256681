"""The SCARA's two arm lengths A1, A2 chosen for speed: the shortest pick-and-place cycle — pick →
place → back, 305 mm apart, lifting 25 mm above each — that its motors can drive.  Longer arms turn
less for the same move, so the cycle gets shorter; but they are heavier and further out, so the motor
torques grow: the torque limits decide.

The task is `studies/tasks/scara_cycle.toml` (robot `studies/tasks/robots/scara_design.toml`, arms
100 … 400 mm; its pick and place points in `scara_cycle_points.csv`).  A design's cycle
(`design.cycle`): IK at both stops and 25 mm above them, the elbow branch chosen for the whole cycle,
straight joint-space segments that rest at each stop, timed in minimum time under the joints' speed
and acceleration limits (`planning.timing`); the motor torques along it by inverse dynamics of the
design's link mass model — uniform tubes whose mass follows each design's lengths, motors at the
joints, a payload at the tool (`design.cycle.masses`).  A design is feasible when it reaches both
points and every peak torque is within its motor's limit.  A sweep maps the cycle time and the torque
over the design plane, differential evolution searches it, and the best design's torques are
recomputed along its trajectory by the SCARA's closed-form dynamics, written out in this script.
Times are wall times measured in this run on this machine.
"""
from __future__ import annotations

import dataclasses
import sys
import tempfile
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

import kin
import studies
from design.cycle import chain_with_masses, evaluate_cycle
from design.optimise import VerifySettings, optimise
from design.sweep import LocalExecutor, best_row, loads_sweep, read_sweep, run_sweep, write_csv
from design.task import load_task
from planning.timing.limits import dense_times
from studies.plots.sweep import plot_cycle_pareto
from studies.report.html import format_value as num
from studies.report.view3d import robot_view
from studies.study import Study, main

NAME = "scara_cycle"
TITLE = "SCARA pick-and-place: arm lengths for the shortest cycle under motor torque limits"

TASK = Path(studies.__file__).parent / "tasks" / "scara_cycle.toml"

# The sweep as a sweep file (docs/design.md, "Sweep files"): save it beside the task file and run it with `rmt sweep`.
SWEEP = """\
name = "scara_cycle"
task = "scara_cycle.toml"
metrics = ["coverage", "structural_length", "cycle_time", "peak_torque", "torque_ratio"]

[sampling]
method = "grid"

[evaluation]
seeds = {seeds}
samples = {samples}

[parameters.A1]
range = [100, 400]
count = {count}

[parameters.A2]
range = [100, 400]
count = {count}
"""


def run(s: Study) -> None:
    with tempfile.TemporaryDirectory(prefix="rmt-scara-cycle-") as scratch:
        study(s, Path(scratch))


def study(s: Study, scratch: Path) -> None:
    settings = VerifySettings(seeds=s.input("IK seeds per target (coverage)", 2),
                              samples=s.input("sampled configurations for the IK seed index", 1000), seed=0)
    sweep_n = s.input("sweep grid points per parameter", 10 if s.quick else 31)
    workers = s.input("sweep worker processes (local executor)", 1 if s.quick else 2)
    de_popsize = s.input("DE population size (per parameter)", 6 if s.quick else 10)
    de_maxiter = s.input("DE generations (at most)", 8 if s.quick else 30)
    per = s.input("check samples per trajectory interval", 50)

    robot = s.robot(TASK.parent / "robots" / "scara_design.toml")
    task = load_task(TASK, robot=robot)
    cyc, c = task.cycle, robot.chain
    mm, deg = 1e3, 180 / np.pi
    P = task.targets.positions
    res: dict = {}

    with s.section("The task"):
        ms = cyc.masses
        s.text(f"Pick at ({', '.join(num(mm * x, '.1f') for x in P[0])}) mm, place at "
               f"({', '.join(num(mm * x, '.1f') for x in P[1])}) mm, {mm * np.linalg.norm(P[1] - P[0]):.0f} mm "
               f"apart, each approached and left {mm * cyc.lift:g} mm above it; the tool rests at both.  The "
               "joint limits and motors below are the same for every design; only A1 and A2 change, and with "
               "them the masses and inertias of the links.")
        units = [("deg", "deg/s", "deg/s²", "N·m", deg), ("deg", "deg/s", "deg/s²", "N·m", deg),
                 ("mm", "mm/s", "mm/s²", "N", mm)]
        s.table(["joint", "speed limit", "acceleration limit", "torque limit", "tube (kg/m)", "motor (kg)"],
                [[j.name, f"{u[4] * v:g} {u[1]}", f"{u[4] * a:g} {u[2]}", f"{t:g} {u[3]}", rho, mot]
                 for j, v, a, t, rho, mot, u in zip(c.joints, cyc.v_max, cyc.a_max, cyc.tau_max, ms.mass_per_length,
                                                    ms.motor_mass, units)],
                caption=f"The motors and the link mass model; payload {ms.payload:g} kg at the tool.  J1's motor "
                        "stands on the base; J2's rides at the elbow, J3's at the end of the forearm.")
        s.code(TASK.read_text(encoding="utf-8"), "studies/tasks/scara_cycle.toml", collapsed=True)
        nominal = c.parameter_values.copy()
        nom = evaluate_cycle(robot, cyc, task.targets, nominal)
        s.text(f"The nominal design (A1 = A2 = {mm * nominal[0]:g} mm) runs the cycle in **{nom.cycle_time:.3f} s**, "
               f"with peak torques {', '.join(f'{n} {t:.1f}' for n, t in zip(nom.joint_names, nom.peak_torque))} "
               f"(N·m, N): {'within' if nom.within_torque else 'over'} the motor limits (largest ratio "
               f"{nom.torque_ratio:.2f}).")
        res["nominal"] = {"A1_mm": mm * nominal[0], "A2_mm": mm * nominal[1], **nom.to_dict()}
        # the same design with its motion timed under the torque limits too (torque = "limit")
        lim = evaluate_cycle(robot, dataclasses.replace(cyc, torque="limit"), task.targets, nominal)
        s.text(f"Timed under the motor torque limits as well (`torque = \"limit\"`: torque rows in the "
               f"time parameterisation), the same design runs the cycle in **{lim.cycle_time:.4f} s** "
               f"({1e3 * (lim.cycle_time - nom.cycle_time):.2f} ms more than {nom.cycle_time:.4f} s) with "
               f"largest torque ratio {lim.torque_ratio:.3f}: the motion slows down only where a motor would "
               f"saturate.  The sweep below keeps the faster rule — "
               f"timing under speed and acceleration limits, torque a constraint of the design — so that a "
               f"design is judged by motors that never saturate.")
        res["nominal_torque_limited"] = lim.to_dict()

    with s.section("Sweep over the arm lengths"):
        text = SWEEP.format(seeds=settings.seeds, samples=settings.samples, count=sweep_n)
        sweep = loads_sweep(text, "scara_cycle sweep", TASK.parent, task=task)
        s.code(text, "The sweep as a sweep file: save it beside the task file and run `rmt sweep FILE`, then "
                     "`rmt sweep-plot DB`.", collapsed=True)
        db = scratch / "sweep.sqlite"
        rep = run_sweep(sweep, db, LocalExecutor(workers=workers))
        meta, rows = read_sweep(db)
        done = [r for r in rows if r["status"] == "done"]
        A = np.array([[r["params"]["A1"], r["params"]["A2"]] for r in done])
        T = np.array([r["metrics"]["cycle_time"] if r["metrics"]["cycle_time"] is not None else np.inf for r in done])
        R = np.array([np.nan if r["metrics"]["torque_ratio"] is None else r["metrics"]["torque_ratio"] for r in done])
        F = np.array([bool(r["metrics"]["feasible"]) for r in done])
        best = best_row(rows, "cycle_time")
        fastest = int(np.argmin(T))
        b_a = np.array([best["params"]["A1"], best["params"]["A2"]])
        s.text(f"{len(rows)} designs ({sweep_n} × {sweep_n} from 100 to 400 mm), {rep.counts['done']} done, "
               f"{rep.counts['failed']} failed, in {rep.time_s:.1f} s on {workers} worker(s).  "
               f"{int(np.isfinite(T).sum())} reach both points; {int(F.sum())} also keep every torque within its "
               f"limit.  The fastest of all, A1 = {mm * A[fastest, 0]:.0f} mm, A2 = {mm * A[fastest, 1]:.0f} mm, "
               f"takes {T[fastest]:.3f} s but needs {R[fastest]:.2f}× a motor's torque; the fastest feasible one, "
               f"**A1 = {mm * b_a[0]:.0f} mm, A2 = {mm * b_a[1]:.0f} mm, {best['objective']:.3f} s**.")
        s.figure(maps_figure(mm * A, T, R, F, mm * b_a, mm * A[fastest]), "maps",
                 "Cycle time (left) and the largest peak torque over its motor's limit (right) over the design "
                 "plane; blank: a point out of reach.  The torque limit (ratio 1) in white; the fastest feasible "
                 "design starred, the fastest of all ringed.")
        png = plot_cycle_pareto(meta, rows, scratch / "cycle_pareto.png",
                                marks=[("fastest feasible", R[np.argmin(np.where(F, T, np.inf))], best["objective"])])
        s.image(png, "Every design's cycle time against its torque ratio: the Pareto front is the price in time of "
                     "weaker motors.")
        s.file("sweep.sqlite", db.read_bytes())
        s.file("sweep.csv", write_csv(db, scratch / "sweep.csv").read_text(encoding="utf-8"))
        res["sweep"] = {"designs": len(rows), "n": sweep_n, "done": rep.counts["done"], "failed": rep.counts["failed"],
                        "reached": int(np.isfinite(T).sum()), "feasible": int(F.sum()), "time_s": rep.time_s,
                        "best": {"A1_mm": mm * b_a[0], "A2_mm": mm * b_a[1], "cycle_time_s": best["objective"]},
                        "fastest_any": {"A1_mm": mm * A[fastest, 0], "A2_mm": mm * A[fastest, 1],
                                        "cycle_time_s": T[fastest], "torque_ratio": R[fastest]}}

    with s.section("Differential evolution"):
        de = optimise(task, method="de", settings=settings, popsize=de_popsize, maxiter=de_maxiter)
        p_de = np.array([de.params[k] for k in c.parameters])
        s.text(f"The cycle time cannot be differentiated through the IK branch choice and the time-optimal "
               f"timing, so the search is derivative-free: scipy's differential evolution (population {de_popsize} "
               f"per parameter, at most {de_maxiter} generations, seeded), infeasible designs penalised by their "
               f"torque excess.  It finds A1 = {mm * p_de[0]:.1f} mm, A2 = {mm * p_de[1]:.1f} mm, "
               f"**{de.objective:.3f} s** ({num(100 * (de.objective / best['objective'] - 1), '+.1f')} % against "
               f"the sweep's best), {'feasible' if de.feasible else 'NOT feasible'}, "
               f"{de.solver['evaluations']} designs in {de.time_s:.1f} s.")
        res["de"] = {"A1_mm": mm * p_de[0], "A2_mm": mm * p_de[1], "cycle_time_s": de.objective,
                     "feasible": de.feasible, "designs": de.solver["evaluations"], "time_s": de.time_s}

    p_best = p_de if de.feasible and de.objective <= best["objective"] else b_a
    with s.section("The best design's cycle"):
        out = evaluate_cycle(robot, cyc, task.targets, p_best)
        dyn = kin.Robot(chain_with_masses(c, p_best, cyc.masses))       # the design with its link masses
        times = np.concatenate([[0.0], np.cumsum(out.segment_times)])
        s.figure(cycle_figure(out, times, dyn), "cycle",
                 "The best design's cycle: joint positions (top) and motor torques over their limits (bottom), "
                 "from the pick through the place and back.")
        path = np.vstack([tr.sample(np.linspace(0, tr.duration, 40))[0] for tr in out.trajectories])
        s.view3d(robot_view(kin.Robot(c.with_parameters(dict(zip(c.parameters, p_best)))), out.q[0], path=path,
                            targets=P), "cycle_3d",
                 "The best design running its cycle (slider: the move), pick and place in green.")
        res["best"] = {"A1_mm": mm * p_best[0], "A2_mm": mm * p_best[1], **out.to_dict()}

    with s.section("Independent check"):
        chk = closed_form_check(out, p_best, cyc, dyn, per)
        s.text(f"The torques along the best design's trajectory, recomputed at {per} times per interval "
               f"({chk['samples']} samples) by the SCARA's closed-form dynamics written in this script — the arm "
               "as two bodies turning about vertical axes, each body's mass, first moment and inertia summed from "
               "its tube, motors, quill and payload, and the quill's force m(q̈3 + g) — differ from the "
               f"library's Newton–Euler by at most **{chk['max_diff']:.2e}** N·m.  On these samples the largest "
               f"torque ratio is {chk['ratio']:.4f}, speed ratio {chk['v_ratio']:.4f}, acceleration ratio "
               f"{chk['a_ratio']:.4f}: every limit holds.")
        res["check"] = chk

    s.results.update(res)
    s.finding(f"Fastest pick-and-place within the motor limits: A1 = {mm * p_best[0]:.0f} mm, A2 = "
              f"{mm * p_best[1]:.0f} mm, cycle {out.cycle_time:.3f} s (nominal 225/225 mm: {nom.cycle_time:.3f} s, "
              f"torque ratio {nom.torque_ratio:.2f}).", ok=out.ok and out.within_torque)
    s.finding(f"The torque limit binds: the fastest design of the sweep ({T[fastest]:.3f} s) needs "
              f"{R[fastest]:.2f}× a motor's torque.", ok=bool(R[fastest] > 1))
    s.finding(f"Closed-form dynamics agree with the library to {chk['max_diff']:.1e} N·m on {chk['samples']} samples; "
              f"every torque, speed and acceleration limit holds there.",
              ok=chk["max_diff"] < 1e-6 and max(chk["ratio"], chk["v_ratio"], chk["a_ratio"]) <= 1 + 1e-6)


def closed_form_check(out, p, cyc, dyn: kin.Robot, per: int) -> dict:
    """The SCARA's torques in closed form along the cycle's trajectories (numpy only), against the
    library's; the largest torque, speed and acceleration ratios on the same dense samples."""
    L1, L2 = p
    rho1, rho2, rho3 = cyc.masses.mass_per_length
    _, M2, M3 = cyc.masses.motor_mass
    pay, rot, g = cyc.masses.payload, cyc.masses.rotor_inertia, 9.81
    d2 = 0.001                                        # J2's DH d offset (1 mm): a tube on J2's axis
    quill = rho3 * 0.200                              # J3's 200 mm stroke
    tip = M3 + quill + pay                            # point masses at the forearm's end
    A1 = rho1 * L1 ** 3 / 3 + M2 * L1 ** 2            # body 1 about J1 (its d rod lies on the axis)
    m2 = rho2 * (L2 + d2) + tip                       # body 2 and what it carries
    S2 = rho2 * L2 ** 2 / 2 + tip * L2                # its first moment about J2, along the forearm
    A2 = rho2 * L2 ** 3 / 3 + tip * L2 ** 2           # its inertia about J2
    diff = ratio = vr = ar = 0.0
    n = 0
    for tr in out.trajectories:
        q, qd, qdd = tr.sample(dense_times(tr.t, per))
        c2, s2 = np.cos(q[:, 1]), np.sin(q[:, 1])
        M11 = A1 + A2 + m2 * L1 ** 2 + 2 * S2 * L1 * c2 + rot[0]
        M12 = A2 + S2 * L1 * c2
        h = S2 * L1 * s2
        tau = np.column_stack([M11 * qdd[:, 0] + M12 * qdd[:, 1] - h * (2 * qd[:, 0] * qd[:, 1] + qd[:, 1] ** 2),
                               M12 * qdd[:, 0] + (A2 + rot[1]) * qdd[:, 1] + h * qd[:, 0] ** 2,
                               (quill + pay) * (qdd[:, 2] + g) + rot[2] * qdd[:, 2]])
        lib = dyn.inverse_dynamics(q, qd, qdd)
        diff = max(diff, float(np.abs(tau - lib).max()))
        ratio = max(ratio, float((np.abs(tau) / cyc.tau_max).max()))
        vr = max(vr, float((np.abs(qd) / cyc.v_max).max()))
        ar = max(ar, float((np.abs(qdd) / cyc.a_max).max()))
        n += len(q)
    return {"max_diff": diff, "ratio": ratio, "v_ratio": vr, "a_ratio": ar, "samples": n}


# ---- figures (matplotlib's Figure API, no pyplot state) -------------------------------------------
def maps_figure(A_mm, T, R, F, best_mm, fastest_mm) -> Figure:
    """Cycle time and torque ratio over the (A1, A2) grid (mm)."""
    fig = Figure(figsize=(11.0, 4.6))
    ux, uy = np.unique(A_mm[:, 0]), np.unique(A_mm[:, 1])
    for k, (Z, label, cmap) in enumerate(((T, "cycle time (s)", "viridis"), (R, "peak |τ| / τ_max", "magma"))):
        ax = fig.add_subplot(1, 2, k + 1)
        G = np.full((len(uy), len(ux)), np.nan)
        G[np.searchsorted(uy, A_mm[:, 1]), np.searchsorted(ux, A_mm[:, 0])] = np.where(np.isfinite(Z), Z, np.nan)
        m = ax.pcolormesh(ux, uy, G, shading="nearest", cmap=cmap)
        fig.colorbar(m, ax=ax, label=label)
        Rg = np.full_like(G, np.nan)
        Rg[np.searchsorted(uy, A_mm[:, 1]), np.searchsorted(ux, A_mm[:, 0])] = R
        if np.nanmin(Rg) < 1 < np.nanmax(Rg):
            ax.contour(ux, uy, Rg, levels=[1.0], colors="white", linewidths=1.5)
        ax.scatter(A_mm[~F, 0], A_mm[~F, 1], s=8, c="0.7", marker="x")
        ax.scatter(*best_mm, marker="*", s=180, c="gold", edgecolors="k", zorder=5, label="fastest feasible")
        ax.scatter(*fastest_mm, s=120, facecolors="none", edgecolors="red", lw=1.5, zorder=5, label="fastest of all")
        ax.set_xlabel("A1 (mm)")
        ax.set_ylabel("A2 (mm)")
        ax.set_title(label)
        ax.legend(loc="upper right", fontsize=7)
    return fig


def cycle_figure(out, starts, dyn: kin.Robot) -> Figure:
    """Joint positions and torques over their limits against time over the whole cycle (``dyn``: the
    design's chain with its masses)."""
    fig = Figure(figsize=(7.4, 6.0))
    ax1, ax2 = fig.add_subplot(2, 1, 1), fig.add_subplot(2, 1, 2)
    for k, (tr, t0) in enumerate(zip(out.trajectories, starts)):
        t = dense_times(tr.t, 4)
        q, qd, qdd = tr.sample(t)
        tau = dyn.inverse_dynamics(q, qd, qdd)
        for j, nm in enumerate(out.joint_names):
            scale, unit = (180 / np.pi, "deg") if out.revolute[j] else (1e3, "mm")
            ax1.plot(t0 + t, scale * q[:, j], c=f"C{j}", label=f"{nm} ({unit})" if k == 0 else None)
            ax2.plot(t0 + t, tau[:, j] / out.tau_max[j], c=f"C{j}", label=nm if k == 0 else None)
    ax1.set_ylabel("joint position")
    ax1.legend(fontsize=8)
    for y in (-1, 1):
        ax2.axhline(y, ls="--", c="k", lw=1)
    ax2.set_ylabel("τ / τ_max")
    ax2.set_xlabel("time (s)")
    ax2.legend(fontsize=8)
    return fig


if __name__ == "__main__":
    raise SystemExit(main(sys.modules[__name__]))
