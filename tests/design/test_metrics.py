"""Design metrics against closed forms: the planar 2R's reachable area 4π·l1·l2 (the converged voxel
area within its boundary bias), the structural length and length index, the GCI at the IK solutions."""
import numpy as np
import pytest

import kin
from design.coverage import coverage
from design.metrics import converged_volume, length_index, structural_length
from design.task import Targets
from design.task.targets import ring_points

ROBOT = "studies/tasks/robots/planar_2r_design.toml"


def test_structural_length_counts_a_and_d():
    assert structural_length(kin.load_chain("scara_rrp")) == pytest.approx(0.225 * 3 + 0.002)
    chain = kin.load_chain(ROBOT)
    assert structural_length(chain, np.array([0.4, 0.9])) == pytest.approx(1.3)


def test_converged_area_of_the_planar_arm():
    robot = kin.load_robot(ROBOT)
    l1, l2 = 0.7, 0.3
    cv = converged_volume(robot, params=np.array([l1, l2]), start=20_000, tolerance=0.01)
    assert cv.converged and cv.dimension == 2
    assert abs(cv.history[-1][1] - cv.history[-2][1]) <= 0.01 * cv.volume
    exact = 4 * np.pi * l1 * l2
    # boundary cells count in full: the bias is at most the perimeter times a cell's diagonal
    perimeter = 2 * np.pi * ((l1 + l2) + (l1 - l2))
    assert abs(cv.volume - exact) <= perimeter * cv.voxel * np.sqrt(2)
    q_l = length_index(robot, np.array([l1, l2]), samples=20_000, tolerance=0.01)
    assert q_l == pytest.approx((l1 + l2) / np.sqrt(cv.volume))


def test_unconverged_volume_says_so():
    cv = converged_volume(kin.load_robot("fanuc_m16ib20"), start=1000, tolerance=1e-4, max_samples=4000)
    assert not cv.converged and cv.samples == 4000 and len(cv.history) == 3


def test_gci_is_the_mean_inverse_condition_at_the_solutions():
    robot = kin.load_robot(ROBOT)
    l1, l2 = 1.0, 0.6
    cov = coverage(robot, Targets(ring_points([0, 0, 0], 0.5, 1.5, (5, 4, 1))), params={"L1": l1, "L2": l2},
                   seeds=2, samples=2000)
    q = cov.q[cov.covered]
    t1, t12 = q[:, 0], q[:, 0] + q[:, 1]
    J = np.stack([np.stack([-l1 * np.sin(t1) - l2 * np.sin(t12), -l2 * np.sin(t12)], -1),
                  np.stack([l1 * np.cos(t1) + l2 * np.cos(t12), l2 * np.cos(t12)], -1)], 1)
    sv = np.linalg.svd(J, compute_uv=False)
    assert cov.gci == pytest.approx(np.mean(sv[:, 1] / sv[:, 0]), abs=1e-9)
