"""Differential evolution on the verified metric: the total-length projection (closed form), a
cross-check of IPOPT on the SCARA reference problem, determinism, and the planar 2R with fixed
total length (the reachable annulus [|l1 − l2|, l1 + l2] covers the ring only when the links are
nearly equal)."""
from dataclasses import replace

import numpy as np
import pytest

import kin
from design.optimise import VerifySettings, optimise
from design.optimise.de import project_total_length
from design.task import Dexterity, Targets, Task
from design.task.targets import box_points, ring_points


def _scara():
    base = kin.load_robot("studies/tasks/robots/scara_design.toml")
    pars = {k: replace(p, bounds=(0.15, 0.30)) for k, p in base.chain.parameters.items()}
    robot = kin.Robot(replace(base.chain, parameters=pars))
    targets = Targets(box_points([0.15, -0.15, -0.15], [0.35, 0.15, -0.15], (3, 3, 1)))
    return Task("scara", robot, targets, Dexterity("sigma_min", 0.08), objective="length")


def test_projection_meets_the_total_length():
    robot = kin.load_robot("studies/tasks/robots/planar_2r_design.toml")
    task = Task("p", robot, Targets(np.zeros((1, 3))), objective="coverage", total_length=2.0)
    P = project_total_length(task, np.array([[0.3, 0.5], [1.0, 0.25]]))
    assert np.allclose(P, [[0.75, 1.25], [1.6, 0.4]])


def test_de_cross_checks_ipopt_on_the_scara():
    task = _scara()
    settings = VerifySettings(seeds=2, samples=500)
    de = optimise(task, method="de", seed=0, settings=settings, popsize=6, maxiter=15)
    ip = optimise(task, method="ipopt", starts=1, settings=settings)
    assert de.feasible and ip.feasible
    assert de.objective == pytest.approx(ip.objective, rel=0.01)
    again = optimise(task, method="de", seed=0, settings=settings, popsize=6, maxiter=15)
    assert again.params == de.params


def test_de_planar_ring_needs_nearly_equal_links():
    robot = kin.load_robot("studies/tasks/robots/planar_2r_design.toml")
    targets = Targets(ring_points([0, 0, 0], 0.0, 1.98, (10, 4, 1)))
    task = Task("planar", robot, targets, objective="coverage", min_coverage=0.0, total_length=2.0)
    res = optimise(task, method="de", seed=2, settings=VerifySettings(seeds=1, samples=500), popsize=5, maxiter=8)
    r_min = 1.98 * np.sqrt(0.05)                 # innermost target radius (area-uniform midpoint)
    assert res.params["L1"] + res.params["L2"] == pytest.approx(2.0)
    assert res.objective == 1.0 and abs(res.params["L1"] - res.params["L2"]) <= r_min
