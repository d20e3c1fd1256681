"""Coverage decided by IK against closed forms: the planar 2R reaches exactly the annulus
|l1 − l2| ≤ r ≤ l1 + l2, and its translational σ_min has a closed form."""
import numpy as np
import pytest

import kin
from design.coverage import coverage, coverage_of_designs
from design.task import Dexterity, Targets, TaskError
from design.task.targets import box_points, ring_points

ROBOT = "studies/tasks/robots/planar_2r_design.toml"


def _annulus_share(l1, l2, r_out, nr):
    """Share of area-uniform ring radii (the targets' construction, re-derived) inside the reachable annulus."""
    r = np.sqrt((np.arange(nr) + 0.5) / nr) * r_out
    return np.mean((r >= abs(l1 - l2)) & (r <= l1 + l2))


@pytest.mark.parametrize("l1,l2", [(0.7, 0.3), (1.0, 0.5)])
def test_ring_coverage_is_the_annulus_fraction(l1, l2):
    robot = kin.load_robot(ROBOT)
    nr = 120
    targets = Targets(ring_points([0, 0, 0], 0.0, 2.0, (nr, 5, 1)))
    cov = coverage(robot, targets, params={"L1": l1, "L2": l2}, seeds=3, samples=4000)
    analytic = ((l1 + l2) ** 2 - (l1 - l2) ** 2) / 2.0 ** 2        # 4 l1 l2 / R²
    assert cov.fraction == pytest.approx(_annulus_share(l1, l2, 2.0, nr), abs=1e-12)
    assert cov.fraction == pytest.approx(analytic, abs=1.0 / nr)
    assert np.all(np.isnan(cov.best[~cov.reached]))


def test_best_sigma_matches_the_closed_form():
    # planar 2R translational Jacobian: σ_min depends on θ2 only; check against a numpy SVD of the closed form
    robot = kin.load_robot(ROBOT)
    l1, l2 = 1.0, 0.6
    targets = Targets(ring_points([0, 0, 0], 0.5, 1.5, (6, 4, 1)))
    cov = coverage(robot, targets, Dexterity("sigma_min", 0.2), params={"L1": l1, "L2": l2}, seeds=2, samples=3000)
    q = cov.q[cov.reached]
    t1, t12 = q[:, 0], q[:, 0] + q[:, 1]
    J = np.stack([np.stack([-l1 * np.sin(t1) - l2 * np.sin(t12), -l2 * np.sin(t12)], -1),
                  np.stack([l1 * np.cos(t1) + l2 * np.cos(t12), l2 * np.cos(t12)], -1)], 1)
    sv = np.linalg.svd(J, compute_uv=False)
    assert np.allclose(cov.best[cov.reached], sv[:, -1], atol=1e-9)
    assert np.array_equal(cov.covered, cov.reached & (np.nan_to_num(cov.best) >= 0.2))


def test_batched_designs_equal_single_runs_and_are_deterministic():
    robot = kin.load_robot(ROBOT)
    targets = Targets(box_points([-1.2, -1.2, 0], [1.2, 1.2, 0], (7, 7, 1)))
    P = np.array([[0.7, 0.3], [0.9, 0.6]])
    batch = coverage_of_designs(robot, targets, None, P, seeds=2, samples=2000, seed=3)
    for p, b in zip(P, batch):
        one = coverage(robot, targets, params=p, seeds=2, samples=2000, seed=3)
        assert np.array_equal(one.covered, b.covered)
        # the same verdict as the closed form: |l1 − l2| ≤ r ≤ l1 + l2
        r = np.linalg.norm(targets.positions[:, :2], axis=1)
        assert np.array_equal(b.covered, (r >= abs(p[0] - p[1]) - 1e-9) & (r <= p.sum() + 1e-9))


def test_axis_requirement_needs_the_rotation():
    # a positioning-only 2R cannot hold the tool axis along x at every target of its reach
    robot = kin.load_robot(ROBOT)
    pts = ring_points([0, 0, 0], 0.5, 0.9, (3, 4, 1))
    free = coverage(robot, Targets(pts), params={"L1": 0.7, "L2": 0.3}, seeds=2, samples=2000)
    axis = coverage(robot, Targets(pts, "axis", np.tile([1.0, 0, 0], (len(pts), 1))),
                    params={"L1": 0.7, "L2": 0.3}, seeds=2, samples=2000)
    assert free.fraction == 1.0 and axis.fraction == 0.0     # the 2R's tool z is always the base z


def test_bad_design_rows_raise():
    robot = kin.load_robot(ROBOT)
    with pytest.raises(TaskError, match="L1 outside its bounds"):
        coverage_of_designs(robot, Targets(np.zeros((1, 3))), None, np.array([[5.0, 0.5]]))


def test_axis_and_cone_solutions_hold_the_tool_axis():
    # FANUC M-16iB/20: the solutions' tool z (from FK, independent of the IK's own residual) is the
    # required axis, or within the cone's half-angle of it
    robot = kin.load_robot("fanuc_m16ib20")
    pts = box_points([1.0, -0.3, 0.3], [1.3, 0.3, 0.6], (2, 2, 2))
    down = np.tile([0.0, 0.0, -1.0], (len(pts), 1))
    tilted = np.tile([np.sin(0.5), 0.0, -np.cos(0.5)], (len(pts), 1))
    for t in (Targets(pts, "axis", down), Targets(pts, "cone", tilted, cone_half_angle=0.3)):
        cov = coverage(robot, t, seeds=2, samples=3000)
        assert cov.fraction == 1.0
        z = robot.fk(cov.q)[:, :3, 2]
        ang = np.arccos(np.clip(np.einsum("ij,ij->i", z, t.axes), -1, 1))
        assert np.all(ang <= (1e-6 if t.orientation == "axis" else t.cone_half_angle + 1e-6))
        assert np.allclose(robot.fk(cov.q)[:, :3, 3], pts, atol=1e-6)
