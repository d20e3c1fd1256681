"""Reference problems of the IPOPT design optimisation, against independent values: the planar 2R
with fixed total length maximises its reach at l1 = l2 (reachable annulus 4π·l1·l2), and the SCARA
arm lengths agree with a brute-force 50 × 50 grid of the same verified metric."""
from dataclasses import replace

import numpy as np
import pytest

import kin
from design.optimise import VerifySettings, optimise
from design.optimise.grid import grid_search
from design.task import Dexterity, Targets, Task, TaskError, load_task
from design.task.targets import box_points, ring_points


def test_planar_fixed_total_length_gives_equal_links():
    robot = kin.load_robot("studies/tasks/robots/planar_2r_design.toml")
    # the disc of radius 1.98 m with its centre: only |l1 − l2| = 0 reaches the centre
    P = np.vstack([[0.0, 0.0, 0.0], ring_points([0, 0, 0], 0.0, 1.98, (20, 5, 1))])
    task = Task("planar", robot, Targets(P), objective="coverage", min_coverage=0.0, total_length=2.0)
    res = optimise(task, starts=2, seed=1, settings=VerifySettings(seeds=2, samples=2000))
    l1, l2 = res.params["L1"], res.params["L2"]
    assert l1 + l2 == pytest.approx(2.0, abs=1e-6)
    assert l1 == pytest.approx(l2, abs=1e-4)
    # verified: every ring target is inside the annulus [|l1 − l2|, l1 + l2]
    assert res.verification.covered[1:].all()
    assert res.solver["starts"][0]["status"] == "Solve_Succeeded"
    assert all(len(h) > 1 for h in res.history)


def test_scara_ipopt_matches_the_grid():
    base = kin.load_robot("studies/tasks/robots/scara_design.toml")
    pars = {k: replace(p, bounds=(0.15, 0.30)) for k, p in base.chain.parameters.items()}
    robot = kin.Robot(replace(base.chain, parameters=pars))
    targets = Targets(box_points([0.15, -0.15, -0.15], [0.35, 0.15, -0.15], (3, 2, 1)), tolerance=1e-6)
    task = Task("scara", robot, targets, Dexterity("sigma_min", 0.08), objective="length")
    settings = VerifySettings(seeds=2, samples=500)
    res = optimise(task, starts=2, seed=0, settings=settings)
    grid = grid_search(task, 50, settings)
    assert res.feasible and res.verification.fraction == 1.0
    assert grid.feasible.any()
    # objective: Σ|a| + |d| = A1 + A2 + 2 mm, re-derived from the parameters
    assert res.objective == pytest.approx(res.params["A1"] + res.params["A2"] + 0.002, abs=1e-12)
    assert res.objective <= grid.best_score * 1.01
    # and not better than the grid's best by more than its resolution (rounding both lengths up)
    assert res.objective >= grid.best_score - grid.spacing.sum() - 1e-9


def test_non_smooth_objective_is_refused_by_ipopt():
    task = load_task("studies/tasks/scara_box.toml")
    with pytest.raises(TaskError, match="not smooth"):
        optimise(replace(task, objective="gci"), method="ipopt", starts=1)
