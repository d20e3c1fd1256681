"""The SCARA's two arm lengths A1, A2 chosen for a task: the shortest arm that reaches every point
of a 200 × 300 mm box of targets with the dexterity σ_min ≥ 0.08 m/rad, found by IPOPT and checked
against a brute-force grid of the same IK-verified metric, differential evolution and the SCARA's
closed form; then a parameter sweep over the whole design plane shows what a shorter arm costs in
coverage (its Pareto front).

The task is `studies/tasks/scara_box.toml` (robot `studies/tasks/robots/scara_design.toml`: the
thesis SCARA of docs/machines.md with its arms made design parameters, 100 … 400 mm).  Every design
any method returns is verified the same way: a target counts as covered when inverse kinematics
finds a configuration inside the joint limits that reaches it with the required σ_min
(`design.coverage`).  The closed form of the SCARA's reach (an annulus |A1 − A2| ≤ r ≤ A1 + A2 cut
by the joint limits, with σ_min a function of the elbow angle; `studies.study.scara`) is computed
beside it as an independent check.  Times are wall times measured in this run on this machine.
"""
from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Patch

import kin
import studies
from design.coverage import coverage
from design.metrics import structural_length
from design.optimise import VerifySettings, optimise
from design.optimise.grid import grid_search
from design.sweep import LocalExecutor, loads_sweep, read_sweep, run_sweep, write_csv
from design.sweep.export import pareto_front
from design.task import load_task
from design.workspace import compute_workspace
from studies.plots.design import design_plane_figure, plot_history
from studies.plots.sweep import plot_pareto
from studies.report.html import format_value as num
from studies.report.view3d import robot_view
from studies.study import Study, main
from studies.study.scara import closed_form_map, closed_form_optimum, scara_covered, scara_sigma

NAME = "scara_design"
TITLE = "SCARA design: arm lengths for coverage, IPOPT against the grid, and a sweep"

TASK = Path(studies.__file__).parent / "tasks" / "scara_box.toml"

# The sweep, written as a sweep file (docs/design.md, "Sweep files") so that it can be copied to a .toml and
# run with `rmt sweep`; the grid count is filled in below.
SWEEP = """\
name = "scara_design"
task = "scara_box.toml"
metrics = ["coverage", "reach", "flips", "gci", "structural_length"]

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
    # plots that write their own PNG and the sweep's database go to a scratch folder; the report keeps copies
    with tempfile.TemporaryDirectory(prefix="rmt-scara-design-") as scratch:
        study(s, Path(scratch))


def study(s: Study, scratch: Path) -> None:
    # ------------------------------------------------------------------------------------- inputs
    # One IK budget for every method: the grid, DE and the sweep evaluate thousands of designs with
    # it, and IPOPT's answer is re-verified with it (and once more with a larger budget below).
    settings = VerifySettings(seeds=s.input("IK seeds per target (verification)", 2),
                              samples=s.input("sampled configurations for the IK seed index", 2000),
                              seed=s.input("verification seed", 0))
    starts = s.input("IPOPT starts (nominal + best screened random designs)", 4)
    grid_n = s.input("brute-force grid points per parameter", 20 if s.quick else 50)
    de_popsize = s.input("DE population size (per parameter)", 6 if s.quick else 8)
    de_maxiter = s.input("DE generations (at most)", 10 if s.quick else 40)
    sweep_n = s.input("sweep grid points per parameter", 10 if s.quick else 30)
    workers = s.input("sweep worker processes (local executor)", 1 if s.quick else 2)
    ws_samples = s.input("workspace samples of the optimised arm (3-D view)", 20_000 if s.quick else 100_000)

    robot = s.robot(TASK.parent / "robots" / "scara_design.toml")
    task = load_task(TASK, robot=robot)
    c = robot.chain
    mm = 1e3                                        # SI → the task file's unit
    P = task.targets.positions
    sigma = task.dexterity.value
    z0 = structural_length(c, np.zeros(len(c.parameters)))    # the fixed d's: tool height at q3 = 0
    bounds = np.array([p.bounds for p in c.parameters.values()])
    results: dict = {}

    with s.section("The task"):
        r = np.hypot(P[:, 0], P[:, 1])
        nx, ny = (len(np.unique(P[:, i])) for i in (0, 1))
        s.text("Every target must be reached, position only, with σ_min of the translational Jacobian at "
               f"least {sigma:g} m/rad there (a margin from the singular stretched and folded arm); among the "
               "designs that do, the shortest structural length Σ(|a|+|d|) wins.")
        s.table(["requirement", "value"], [
            ["targets", f"{len(P)}: a {nx} × {ny} grid, x {mm * P[:, 0].min():.0f} … {mm * P[:, 0].max():.0f} mm, "
                        f"y {num(mm * P[:, 1].min(), '.0f')} … {num(mm * P[:, 1].max(), '.0f')} mm, "
                        f"z = {num(mm * P[0, 2], '.0f')} mm"],
            ["target radii (from the J1 axis)", f"{mm * r.min():.1f} … {mm * r.max():.1f} mm"],
            ["orientation", f"{task.targets.orientation} (position only)"],
            ["position tolerance", f"{mm * task.targets.tolerance:g} mm"],
            ["dexterity", f"{task.dexterity.kind}: σ_min ≥ {sigma:g} m/rad at every target"],
            ["coverage required", f"{100 * task.min_coverage:g} % of the targets"],
            ["objective", f"{task.objective}: minimise Σ(|a|+|d|) = A1 + A2 + {mm * z0:g} mm"],
            *[[f"design parameter {k}", f"{mm * p.bounds[0]:g} … {mm * p.bounds[1]:g} mm (nominal {mm * v:g} mm)"]
              for (k, p), v in zip(c.parameters.items(), c.parameter_values)],
            *[[f"joint {j.name} limits", f"{num(lo, 'g')} … {num(hi, 'g')} rad" if j.is_revolute else
               f"{num(mm * lo, 'g')} … {num(mm * hi, 'g')} mm"] for j, lo, hi in zip(c.joints, c.lower, c.upper)],
        ], caption="The design task `scara_box` (file below).")
        s.code(TASK.read_text(encoding="utf-8"), "studies/tasks/scara_box.toml", collapsed=True)
        nominal = c.parameter_values.copy()
        cov0 = coverage(robot, task.targets, task.dexterity, nominal, settings.seeds, settings.samples, settings.seed)
        s.figure(task_figure(mm * P, tuple(nominal), c.lower, c.upper, sigma), "task",
                 "The targets seen from above, with the region the nominal design (A1 = A2 = 225 mm) reaches "
                 f"with σ_min ≥ {sigma:g} m/rad shaded (closed form).")
        s.text(f"The nominal design (A1 = {mm * nominal[0]:g} mm, A2 = {mm * nominal[1]:g} mm, Σ(|a|+|d|) = "
               f"{mm * structural_length(c, nominal):.1f} mm) covers **{100 * cov0.fraction:.0f} %** of the targets "
               "(IK-verified)" + (": it does the job; the sections below find how much shorter it can be."
                                   if cov0.fraction == 1 else "."))
        results["task"] = {"name": task.name, "targets": len(P), "radius_mm": [mm * r.min(), mm * r.max()],
                           "z_mm": mm * P[0, 2], "orientation": task.targets.orientation,
                           "sigma_min_m_per_rad": sigma, "min_coverage": task.min_coverage,
                           "objective": task.objective, "fixed_length_mm": mm * z0}
        results["nominal"] = {"A1_mm": mm * nominal[0], "A2_mm": mm * nominal[1],
                              "length_mm": mm * structural_length(c, nominal),
                              "coverage_percent": 100 * cov0.fraction}

    with s.section("IPOPT"):
        s.text(f"One NLP over (A1, A2) and one configuration per target (`design.optimise`, exact derivatives "
               f"by CasADi), started from the nominal design and the {starts - 1} best of "
               f"{8 * (starts - 1)} screened random designs; the best start's answer is then verified by the "
               "coverage metric, as every other design in this report.")
        ip = optimise(task, method="ipopt", starts=starts, settings=settings)
        p_ip = np.array([ip.params[k] for k in c.parameters])
        # a second verification with a much larger IK budget: the answer must not depend on the budget
        cov_big = coverage(robot, task.targets, task.dexterity, p_ip, seeds=8, samples=50_000, seed=1)
        rows = [[i, *(mm * np.array(list(st["p0"].values()))), *(mm * np.array(list(st["p"].values()))),
                 mm * st["objective"], st["status"], st["iterations"], round(st["time_s"], 3),
                 100 * st["verified_coverage"]] for i, st in enumerate(ip.solver["starts"])]
        s.table(["start", "A1 start (mm)", "A2 start (mm)", "A1 (mm)", "A2 (mm)", "Σ(|a|+|d|) (mm)", "IPOPT status",
                 "iterations", "time (s)", "verified coverage (%)"], rows,
                caption=f"The IPOPT starts; start {ip.solver['best_start']} is kept.", fmt=".6g")
        hist_png = scratch / "ipopt_history.png"
        plot_history([[mm * v for v in h] for h in ip.history], hist_png, "objective Σ(|a|+|d|) (mm)",
                     "IPOPT: objective per iteration")
        s.image(hist_png, "IPOPT's objective per iteration, one line per start.  The second hump is the re-solve "
                          "from the first answer with every target's configuration re-seeded by IK (kept only if it "
                          "improves); IPOPT's iterates meet the constraints only at convergence, so the objective "
                          "rises on the way.")
        L_ip = mm * ip.objective
        s.text(f"IPOPT's design: **A1 = {mm * p_ip[0]:.2f} mm, A2 = {mm * p_ip[1]:.2f} mm, Σ(|a|+|d|) = "
               f"{L_ip:.2f} mm**, {100 * ip.verification.fraction:.0f} % of the targets covered by the metric "
               f"({ip.verification.flips} seed-dependent verdicts); with 8 IK seeds and 50 000 samples "
               f"{100 * cov_big.fraction:.0f} % ({cov_big.flips} flips).  Time {ip.time_s:.2f} s, including the "
               "screening of the starts and the verification.")
        s.figure(optimum_figure(mm * P, tuple(p_ip), ip.verification, c.lower, c.upper, sigma), "optimum",
                 "The optimum seen from above: where it reaches with the required dexterity (closed form, shaded), "
                 "each target coloured by the best σ_min IK found there, and the arm at the least dexterous "
                 "target — the far corners, which set the length.")
        results["ipopt"] = {"A1_mm": mm * p_ip[0], "A2_mm": mm * p_ip[1], "length_mm": L_ip,
                            "feasible": ip.feasible, "coverage_percent": 100 * ip.verification.fraction,
                            "flips": ip.verification.flips, "coverage_percent_large_budget": 100 * cov_big.fraction,
                            "min_sigma_m_per_rad": float(np.nanmin(ip.verification.best)),
                            "starts": len(ip.solver["starts"]), "best_start": ip.solver["best_start"],
                            "statuses": [st["status"] for st in ip.solver["starts"]],
                            "iterations": sum(st["iterations"] for st in ip.solver["starts"]), "time_s": ip.time_s}

        # the optimised arm in 3-D: its sampled workspace, the task's targets, the arm half-folded
        opt_robot = kin.Robot(c.with_parameters(ip.params))
        ws_opt = compute_workspace(opt_robot, n_samples=ws_samples, seed=0)
        q_view = np.clip([0.3, 1.2, 0.5 * (c.lower[2] + c.upper[2])], c.lower, c.upper)
        s.view3d(robot_view(opt_robot, q_view, cloud=ws_opt.positions, near_singular=ws_opt.near_singular,
                            targets=task.targets.positions),
                 "optimum_3d", f"The optimised arm (A1 = {mm * p_ip[0]:.1f} mm, A2 = {mm * p_ip[1]:.1f} mm) with "
                               f"{ws_opt.n_samples:,} sampled tool positions (near-singular in red) and the task's "
                               "targets (green): drag to turn, scroll to zoom.")

    with s.section("Brute-force grid"):
        t0 = time.perf_counter()
        grid = grid_search(task, grid_n, settings)
        t_grid = time.perf_counter() - t0
        ib = int(np.argmin(grid.score))
        L_grid = mm * structural_length(c, grid.best)
        gap = 100 * (L_ip - L_grid) / L_grid
        ratio = t_grid / ip.time_s
        s.text(f"Every design of a {grid_n} × {grid_n} grid over the bounds ({len(grid.P)} designs, spacing "
               f"{mm * grid.spacing[0]:.2f} mm) verified by the same metric: {int(grid.feasible.sum())} cover every "
               f"target.  The shortest: A1 = {mm * grid.best[0]:.2f} mm, A2 = {mm * grid.best[1]:.2f} mm, "
               f"Σ(|a|+|d|) = {L_grid:.2f} mm, in {t_grid:.2f} s.  IPOPT's design is **{num(gap, '+.3f')} %** "
               f"against it and took {ratio:.1f}× less time (both measured in this run).")
        results["grid"] = {"n": grid_n, "designs": len(grid.P), "spacing_mm": mm * float(grid.spacing[0]),
                           "feasible_designs": int(grid.feasible.sum()), "A1_mm": mm * grid.best[0],
                           "A2_mm": mm * grid.best[1], "length_mm": L_grid, "feasible": bool(grid.feasible[ib]),
                           "time_s": t_grid}
        results["ipopt_vs_grid"] = {"gap_percent": gap, "time_ratio": ratio}

    with s.section("Differential evolution"):
        # a derivative-free cross-check on the verified metric itself (whole generations in one IK batch)
        de = optimise(task, method="de", settings=settings, popsize=de_popsize, maxiter=de_maxiter)
        p_de = np.array([de.params[k] for k in c.parameters])
        L_de = mm * de.objective
        s.text(f"scipy's differential evolution (population {de_popsize} per parameter, at most {de_maxiter} "
               f"generations, seeded): A1 = {mm * p_de[0]:.2f} mm, A2 = {mm * p_de[1]:.2f} mm, Σ(|a|+|d|) = "
               f"{L_de:.2f} mm ({num(100 * (L_de - L_ip) / L_ip, '+.3f')} % against IPOPT), {de.solver['evaluations']} "
               f"designs verified in {de.time_s:.2f} s.")
        results["de"] = {"A1_mm": mm * p_de[0], "A2_mm": mm * p_de[1], "length_mm": L_de, "feasible": de.feasible,
                         "coverage_percent": 100 * de.verification.fraction, "gap_to_ipopt_percent":
                         100 * (L_de - L_ip) / L_ip, "designs": de.solver["evaluations"],
                         "generations": de.solver["generations"], "time_s": de.time_s}

    with s.section("Closed-form check"):
        # the SCARA's reach in closed form (studies.study.scara): independent of IK and of the optimisers
        cf = closed_form_optimum(P, c.lower, c.upper, sigma, z0, bounds)
        L_cf = mm * (cf.sum() + z0)
        cf_ip = scara_covered([p_ip[0]], [p_ip[1]], P, c.lower, c.upper, sigma, z0)[0]
        grid_cf = scara_covered(grid.P[:, 0], grid.P[:, 1], P, c.lower, c.upper, sigma, z0).all(axis=1)
        disagree = int(np.sum(grid_cf != grid.feasible))
        axis = np.linspace(bounds[0, 0], bounds[0, 1], 301)
        share = closed_form_map(axis, P, c.lower, c.upper, sigma, z0)
        A1g, A2g = np.repeat(axis, len(axis)), np.tile(axis, len(axis))     # share.ravel()'s order
        flat = (share.ravel() >= 1) & (A1g + A2g <= cf.sum() + 1e-3)          # covering, ≤ 1 mm longer
        valley = [mm * A1g[flat].min(), mm * A1g[flat].max()] if flat.any() else [None, None]
        s.text(f"In closed form the shortest design covering every target is A1 = {mm * cf[0]:.2f} mm, "
               f"A2 = {mm * cf[1]:.2f} mm, **Σ(|a|+|d|) = {L_cf:.2f} mm** (to 0.01 mm); IPOPT's is "
               f"{num(L_ip - L_cf, '+.2f')} mm from it (its σ_min constraint carries a small margin), and the closed "
               f"form covers {int(cf_ip.sum())} of the {len(P)} targets at IPOPT's design.  On the "
               f"{grid_n} × {grid_n} grid, IK and the closed form disagree on {disagree} of {len(grid.P)} designs' "
               f"feasibility.  The optimum is a flat valley: designs with A1 from {valley[0]:.0f} to "
               f"{valley[1]:.0f} mm cover every target and are at most 1 mm longer than the shortest, which is "
               "why the methods land at different A1 with nearly the same length — the split between the arms "
               "is free to be chosen for something else (stiffness, inertia).")
        marks = [(f"IPOPT ({L_ip:.1f} mm)", mm * p_ip[0], mm * p_ip[1], "*", "gold"),
                 (f"grid best ({L_grid:.1f} mm)", mm * grid.best[0], mm * grid.best[1], "s", "tab:purple"),
                 (f"DE ({L_de:.1f} mm)", mm * p_de[0], mm * p_de[1], "^", "tab:green"),
                 (f"closed form ({L_cf:.1f} mm)", mm * cf[0], mm * cf[1], "P", "tab:red")]
        s.figure(design_plane_figure(mm * axis, share, mm * grid.P, grid.feasible, grid_cf, marks, mm * z0,
                                           L_cf), "design_plane",
                 "The design plane: the share of targets covered in closed form (grey scale) with its 100 % "
                 "boundary (green), the grid designs the IK metric finds feasible, the line of the shortest "
                 "length, and each method's answer.")
        results["closed_form"] = {"A1_mm": mm * cf[0], "A2_mm": mm * cf[1], "length_mm": L_cf,
                                  "resolution_mm": 0.01, "covered_at_ipopt": int(cf_ip.sum()),
                                  "ipopt_minus_closed_form_mm": L_ip - L_cf, "grid_disagreements": disagree,
                                  "valley_A1_mm": valley}

    with s.section("Parameter sweep"):
        sweep = loads_sweep(SWEEP.format(seeds=settings.seeds, samples=settings.samples, count=sweep_n),
                            "scara_design sweep", TASK.parent, task=task)
        s.code(SWEEP.format(seeds=settings.seeds, samples=settings.samples, count=sweep_n),
               "The sweep as a sweep file (docs/design.md, \"Sweep files\"): save it beside the task file and run "
               "`rmt sweep FILE --workers 2`.", collapsed=True)
        db = scratch / "sweep.sqlite"
        rep = run_sweep(sweep, db, LocalExecutor(workers=workers))
        meta, srows = read_sweep(db)
        done = [q for q in srows if q["status"] == "done"]
        L = np.array([q["metrics"]["structural_length"] for q in done])
        C = np.array([q["metrics"]["coverage"] for q in done])
        front = np.flatnonzero(pareto_front(L, C))
        front = front[np.argsort(L[front])]
        pareto = [{"A1_mm": mm * done[i]["params"]["A1"], "A2_mm": mm * done[i]["params"]["A2"],
                   "length_mm": mm * L[i], "coverage": C[i], "gci": done[i]["metrics"]["gci"]} for i in front]
        full = [i for i in range(len(done)) if done[i]["metrics"]["feasible"]]
        short = min(full, key=lambda i: L[i]) if full else None
        s.text(f"{len(srows)} designs ({sweep_n} × {sweep_n} over the bounds), {rep.counts['done']} done and "
               f"{rep.counts['failed']} failed, on {workers} local worker process{'es' if workers > 1 else ''} in "
               f"{rep.time_s:.1f} s ({rep.rate:.0f} designs/s).  The store is `sweep.sqlite` (open it with "
               "`rmt sweep-plot sweep.sqlite` or `design.sweep.sweep_table`), the table `sweep.csv`.  The Pareto "
               f"front of coverage against length holds **{len(front)} designs**; no design of the sweep shorter "
               f"than {pareto[-1]['length_mm']:.1f} mm covers every target, and IPOPT's optimum ({L_ip:.1f} mm) lies "
               "between the sweep's grid points.")
        s.table(["A1 (mm)", "A2 (mm)", "Σ(|a|+|d|) (mm)", "coverage (%)", "GCI"],
                [[q["A1_mm"], q["A2_mm"], q["length_mm"], 100 * q["coverage"], q["gci"]] for q in pareto],
                caption="The Pareto front: no other design of the sweep is as short with as much coverage.  GCI: "
                        "the mean inverse condition number 1/κ of the translational Jacobian over the covered "
                        "targets.")
        png = plot_pareto(meta, srows, scratch / "pareto.png",
                          marks=[(f"IPOPT optimum ({L_ip:.1f} mm)", ip.objective, ip.verification.fraction)])
        s.image(png, "Coverage against structural length of every design of the sweep, the Pareto front in red, "
                     "IPOPT's optimum starred: it lies left of every sweep design with full coverage.")
        s.file("sweep.sqlite", db.read_bytes())
        s.file("sweep.csv", write_csv(db, scratch / "sweep.csv").read_text(encoding="utf-8"))
        results["sweep"] = {"designs": len(srows), "n": sweep_n, "done": rep.counts["done"],
                            "failed": rep.counts["failed"], "workers": workers, "time_s": rep.time_s,
                            "designs_per_s": rep.rate, "pareto": pareto, "pareto_size": len(front),
                            "shortest_feasible": None if short is None else
                            {"A1_mm": mm * done[short]["params"]["A1"], "A2_mm": mm * done[short]["params"]["A2"],
                             "length_mm": mm * L[short]}}

    s.results.update(results)
    # ---------------------------------------------------------------------------------------- findings
    s.finding(f"Shortest SCARA for the box: A1 = {mm * p_ip[0]:.1f} mm, A2 = {mm * p_ip[1]:.1f} mm, "
              f"Σ(|a|+|d|) = {L_ip:.1f} mm (IPOPT), {100 * ip.verification.fraction:.0f} % of the targets covered with "
              f"σ_min ≥ {sigma:g} m/rad by the IK metric and {int(cf_ip.sum())} of {len(P)} in closed form "
              f"(nominal: {results['nominal']['length_mm']:.0f} mm).",
              ok=ip.feasible and bool(cf_ip.all()))
    s.finding(f"Against the {grid_n} × {grid_n} grid's best ({L_grid:.1f} mm): {num(gap, '+.2f')} %, in "
              f"{ratio:.0f}× less time; differential evolution {L_de:.1f} mm; closed form {L_cf:.2f} mm.",
              ok=gap <= 1.0 and abs(L_ip - L_cf) <= 0.005 * L_cf)
    s.finding(f"Sweep of {len(srows)} designs on {workers} worker{'s' if workers > 1 else ''}: a Pareto front of "
              f"{len(front)} designs from {pareto[0]['length_mm']:.0f} mm ({100 * pareto[0]['coverage']:.0f} %) to "
              f"{pareto[-1]['length_mm']:.0f} mm ({100 * pareto[-1]['coverage']:.0f} %).",
              ok=rep.counts["failed"] == 0)


# ---- figures (matplotlib's Figure API, no pyplot state) -------------------------------------------
def arm_points(l1: float, l2: float, q1: float, q2: float) -> np.ndarray:
    """Base, elbow and tool of the arm in the horizontal plane (3, 2), in the units of l1, l2."""
    elbow = l1 * np.array([np.cos(q1), np.sin(q1)])
    return np.array([[0.0, 0.0], elbow, elbow + l2 * np.array([np.cos(q1 + q2), np.sin(q1 + q2)])])


def _region(ax, l1: float, l2: float, lower, upper, sigma_min: float, lim: float, colour: str, label: str):
    """Shade the horizontal region (mm axes) where the design (l1, l2 m) reaches with σ_min ≥ the
    threshold, in closed form; returns a legend handle."""
    g = np.linspace(-lim, lim, 401)
    X, Y = np.meshgrid(g, g)
    sig = scara_sigma([l1], [l2], np.column_stack([X.ravel(), Y.ravel()]) / 1e3, lower, upper)[0].reshape(X.shape)
    ok = np.nan_to_num(sig, nan=-1.0) >= sigma_min
    ax.contourf(X, Y, ok.astype(float), levels=[0.5, 1.5], colors=[colour], alpha=0.35)
    ax.contour(X, Y, ok.astype(float), levels=[0.5], colors=[colour], linewidths=1.0)
    return Patch(facecolor=colour, alpha=0.35, edgecolor=colour, label=label)


def _plane_axes(ax, lim: float):
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.ticklabel_format(useOffset=False)
    ax.grid(alpha=0.3)


def task_figure(positions_mm: np.ndarray, nominal_m: tuple[float, float], lower, upper, sigma_min: float) -> Figure:
    """The targets seen from above, the box they fill, the radii they span, and where the nominal
    design reaches them with the required dexterity (closed form)."""
    fig = Figure(figsize=(7.0, 6.2))
    ax = fig.add_subplot(111)
    lim = 1.15 * 1e3 * (nominal_m[0] + nominal_m[1])
    h = _region(ax, *nominal_m, lower, upper, sigma_min, lim, "tab:green",
                f"nominal A1 = {1e3 * nominal_m[0]:.0f}, A2 = {1e3 * nominal_m[1]:.0f} mm: "
                f"σ_min ≥ {sigma_min:g} m/rad")
    lo, hi = positions_mm[:, :2].min(axis=0), positions_mm[:, :2].max(axis=0)
    box, = ax.plot([lo[0], hi[0], hi[0], lo[0], lo[0]], [lo[1], lo[1], hi[1], hi[1], lo[1]], "k-", lw=1.0,
                   label="target box")
    pts = ax.scatter(positions_mm[:, 0], positions_mm[:, 1], s=22, c="tab:blue", zorder=3,
                     label=f"{len(positions_mm)} targets")
    r = np.hypot(positions_mm[:, 0], positions_mm[:, 1])
    t = np.linspace(-np.pi, np.pi, 361)
    circ = None
    for rad in (r.min(), r.max()):
        circ, = ax.plot(rad * np.cos(t), rad * np.sin(t), "k--", lw=0.8,
                        label=f"target radii {r.min():.0f} … {r.max():.0f} mm")
    base = ax.scatter([0], [0], marker="s", s=50, c="k", zorder=4, label="base (J1 axis)")
    _plane_axes(ax, lim)
    ax.set_title(f"the task seen from above (targets at z = {positions_mm[0, 2]:.0f} mm)")
    ax.legend(handles=[pts, box, circ, h, base], loc="lower left", fontsize=8)
    return fig


def optimum_figure(positions_mm: np.ndarray, design_m: tuple[float, float], cov, lower, upper,
                   sigma_min: float) -> Figure:
    """The optimum seen from above: where it reaches with the required dexterity (closed form,
    shaded), the targets coloured by the IK-verified best σ_min, and the arm at the target with the
    smallest σ_min (the one that sets the length)."""
    fig = Figure(figsize=(7.4, 6.2))
    ax = fig.add_subplot(111)
    l1, l2 = design_m
    lim = 1.15 * 1e3 * (l1 + l2)
    h = _region(ax, l1, l2, lower, upper, sigma_min, lim, "tab:green",
                f"σ_min ≥ {sigma_min:g} m/rad (closed form)")
    ok = cov.covered
    handles = [h]
    if ok.any():
        sc = ax.scatter(positions_mm[ok, 0], positions_mm[ok, 1], c=cov.best[ok], cmap="viridis", s=30, zorder=3,
                        edgecolors="k", linewidths=0.4, label="target, covered (IK)")
        fig.colorbar(sc, ax=ax, label="best σ_min at the target (m/rad)", shrink=0.8)
        handles.append(sc)
    if (~ok).any():
        handles.append(ax.scatter(positions_mm[~ok, 0], positions_mm[~ok, 1], c="red", marker="x", s=30, zorder=3,
                                  label="target, not covered"))
    k = int(np.nanargmin(np.where(ok, cov.best, np.inf))) if ok.any() else 0
    arm = arm_points(1e3 * l1, 1e3 * l2, cov.q[k, 0], cov.q[k, 1])
    line, = ax.plot(arm[:, 0], arm[:, 1], "-o", c="tab:red", lw=2.5, ms=5, zorder=4,
                    label=f"arm at the least dexterous target (σ_min {cov.best[k]:.3f} m/rad)")
    handles.append(line)
    _plane_axes(ax, lim)
    ax.set_title(f"optimum A1 = {1e3 * l1:.1f} mm, A2 = {1e3 * l2:.1f} mm: {100 * cov.fraction:.0f} % covered")
    ax.legend(handles=handles, loc="lower left", fontsize=8)
    return fig


if __name__ == "__main__":
    raise SystemExit(main(sys.modules[__name__]))
