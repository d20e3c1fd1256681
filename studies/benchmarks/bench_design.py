"""Design benchmark: coverage, IPOPT, the brute-force grid and differential evolution on the
bundled reference tasks.

Run as ``python -m studies.benchmarks.bench_design [--json] [--quick]`` (part of ``make bench``).
Figures (all wall times on this machine; provisional when it is loaded):

* time per verified target: ``rmt coverage``'s metric (IK from nearest-neighbour seeds) on the
  SCARA box (position only) and on the FANUC weld cell (tool axis, 4 spins per target);
* SCARA (``scara_box``): IPOPT (4 starts, answer re-verified) against a brute-force grid of
  50 × 50 designs (``--quick``: 20 × 20) under the same verified metric — time ratio (target ≥ 20)
  and objective gap (target: IPOPT within 1 % of the grid);
* differential evolution against IPOPT on the same task: objective gap and time;
* the planar 2R with fixed total length (``planar_ring``): the optimised L1, L2;
* the FANUC M-16iB/20 weld cell (``fanuc_weld_cell``): a2, d4, verified coverage, GCI, time;
* the joint-type enumeration (``arch3_box``): the ranking and its time.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from design.architecture import optimise_architectures
from design.coverage import coverage
from design.optimise import VerifySettings, optimise
from design.optimise.grid import grid_search
from design.task import load_task
from studies.jsonio import dump

TASKS = Path(__file__).resolve().parent.parent / "tasks"     # the bundled task files, from any directory


def _timed(f, *a, **k):
    t0 = time.perf_counter()
    out = f(*a, **k)
    return out, time.perf_counter() - t0


def run(quick: bool = False) -> dict:
    settings = VerifySettings(seeds=2, samples=2000)
    fig: dict = {}
    scara = load_task(f"{TASKS}/scara_box.toml")
    fanuc = load_task(f"{TASKS}/fanuc_weld_cell.toml")
    for name, task in (("scara_box", scara), ("fanuc_weld_cell", fanuc)):
        coverage(task.robot, task.targets, task.dexterity, seeds=4, samples=2000)       # warm-up (compile)
        cov, dt = _timed(coverage, task.robot, task.targets, task.dexterity, seeds=4, samples=20_000)
        fig[f"coverage_{name}"] = {"targets": len(task.targets), "seeds": 4, "time_s": dt,
                                   "ms_per_target": 1e3 * dt / len(task.targets),
                                   "coverage_percent": 100 * cov.fraction, "flips": cov.flips}
    ip, t_ip = _timed(optimise, scara, starts=4, settings=settings)
    n = 20 if quick else 50
    grid, t_grid = _timed(grid_search, scara, n, settings)
    de, t_de = _timed(optimise, scara, method="de", settings=settings, popsize=8, maxiter=20 if quick else 40)
    fig["scara_ipopt_vs_grid"] = {
        "grid": f"{n}x{n}", "ipopt_objective_m": ip.objective, "grid_objective_m": grid.best_score,
        "gap_percent": 100 * (ip.objective - grid.best_score) / grid.best_score,
        "ipopt_time_s": t_ip, "grid_time_s": t_grid, "time_ratio": t_grid / t_ip,
        "ipopt_params_m": ip.params, "grid_params_m": dict(zip(ip.params, grid.best.tolist())),
        "ipopt_feasible": ip.feasible, "within_1_percent": ip.objective <= 1.01 * grid.best_score,
        "at_least_20x": t_grid / t_ip >= 20}
    fig["scara_de_vs_ipopt"] = {"de_objective_m": de.objective, "ipopt_objective_m": ip.objective,
                                "gap_percent": 100 * (de.objective - ip.objective) / ip.objective,
                                "de_time_s": t_de, "de_designs_verified": de.solver["evaluations"],
                                "de_feasible": de.feasible}
    planar = load_task(f"{TASKS}/planar_ring.toml")
    pr, t_pr = _timed(optimise, planar, starts=4, settings=settings)
    fig["planar_ring"] = {"L1_m": pr.params["L1"], "L2_m": pr.params["L2"], "coverage_percent": 100 * pr.objective,
                          "time_s": t_pr}
    fr, t_fr = _timed(optimise, fanuc, starts=2 if quick else 4, settings=VerifySettings(seeds=4, samples=20_000))
    fig["fanuc_weld_cell"] = {"a2_m": fr.params["A2"], "d4_m": fr.params["D4"], "nominal_m": {"a2": 0.770, "d4": 0.740},
                              "structural_length_m": fr.objective, "coverage_percent": 100 * fr.verification.fraction,
                              "flips": fr.verification.flips, "gci": fr.verification.gci, "feasible": fr.feasible,
                              "time_s": t_fr}
    arch = load_task(f"{TASKS}/arch3_box.toml")
    rank, t_ar = _timed(optimise_architectures, arch, starts=1, settings=settings)
    fig["arch3_box"] = {"ranking": [[a, r.feasible, 100 * r.verification.fraction, r.objective]
                                    for a, r in ((a, rank.results[a]) for a in rank.order)], "time_s": t_ar}
    return fig


def report(fig: dict) -> str:
    g, d = fig["scara_ipopt_vs_grid"], fig["scara_de_vs_ipopt"]
    lines = [f"design benchmark (wall times; load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs)"]
    for k in ("coverage_scara_box", "coverage_fanuc_weld_cell"):
        c = fig[k]
        lines.append(f"  {k[9:]:<16} {c['targets']} targets × {c['seeds']} seeds: {c['ms_per_target']:.1f} ms per "
                     f"verified target, {c['coverage_percent']:.1f} % covered, {c['flips']} flip")
    lines.append(f"  SCARA IPOPT {g['ipopt_objective_m']:.6f} m in {g['ipopt_time_s']:.2f} s; grid {g['grid']} "
                 f"{g['grid_objective_m']:.6f} m in {g['grid_time_s']:.1f} s: gap {g['gap_percent']:+.3f} % "
                 f"[{'PASS' if g['within_1_percent'] else 'MISS'} ≤ 1 %], {g['time_ratio']:.0f}× sooner "
                 f"[{'PASS' if g['at_least_20x'] else 'MISS'} ≥ 20×]")
    lines.append(f"  SCARA DE {d['de_objective_m']:.6f} m in {d['de_time_s']:.1f} s "
                 f"({d['de_designs_verified']} designs): "
                 f"{d['gap_percent']:+.3f} % against IPOPT")
    p = fig["planar_ring"]
    lines.append(f"  planar 2R, L1 + L2 = 2 m: L1 = {p['L1_m']:.4f}, L2 = {p['L2_m']:.4f} m, "
                 f"{p['coverage_percent']:.1f} % "
                 f"covered, {p['time_s']:.2f} s")
    f = fig["fanuc_weld_cell"]
    lines.append(f"  FANUC weld cell: a2 = {f['a2_m']:.4f} m, d4 = {f['d4_m']:.4f} m (nominal 0.770, 0.740), "
                 f"Σ(|a|+|d|) = {f['structural_length_m']:.4f} m, {f['coverage_percent']:.1f} % covered, "
                 f"GCI {f['gci']:.3f}, {f['time_s']:.1f} s")
    a = fig["arch3_box"]
    lines.append(f"  architectures (3-joint box), {a['time_s']:.1f} s: " +
                 ", ".join(f"{n} {'✓' if ok else '✗'} {c:.0f} % {o:.3f} m" for n, ok, c, o in a["ranking"]))
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m studies.benchmarks.bench_design", description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object with all figures")
    ap.add_argument("--quick", action="store_true", help="a 20 × 20 grid and fewer starts (a smoke run)")
    args = ap.parse_args(argv)
    fig = run(args.quick)
    print(dump(fig) if args.json else report(fig))
    return 0


if __name__ == "__main__":
    sys.exit(main())
