"""Under a σ_min floor a singular factor keeps its sign along every valid joint path: start and goal
with opposite signs of one exact factor are proven apart (planning.certify.signs), checked against the
UR5e's factors written out from its DH numbers and a plain-numpy Jacobian."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from kin.transforms import make_transform, rpy_to_matrix
from planning.certify.cells import free_cells
from planning.certify.signs import Separator, floor_factors, sign_separation
from planning.ompl.planner import plan

D1, A2, A3, D4, D5, D6 = 0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996      # UR5e, m
FLOOR = 1e-3


def sigma_numpy(q) -> float:
    """σ_min of the UR5e's geometric Jacobian at q (rad), standard DH typed in from its data sheet."""
    alpha = [math.pi / 2, 0, 0, math.pi / 2, -math.pi / 2, 0]
    a = [0, A2, A3, 0, 0, 0]
    d = [D1, 0, 0, D4, D5, D6]
    T = np.eye(4)
    frames = [T]
    for i in range(6):
        ct, st, ca, sa = math.cos(q[i]), math.sin(q[i]), math.cos(alpha[i]), math.sin(alpha[i])
        T = T @ np.array([[ct, -st * ca, st * sa, a[i] * ct], [st, ct * ca, -ct * sa, a[i] * st],
                          [0, sa, ca, d[i]], [0, 0, 0, 1]])
        frames.append(T)
    p = frames[-1][:3, 3]
    J = np.array([np.concatenate([np.cross(F[:3, 2], p - F[:3, 3]), F[:3, 2]]) for F in frames[:-1]]).T
    return float(np.linalg.svd(J, compute_uv=False)[-1])


def shoulder(q) -> float:
    """The UR's shoulder factor (the wrist centre over the base axis), from the DH numbers."""
    return D5 * math.sin(q[1] + q[2] + q[3]) + A2 * math.cos(q[1]) + A3 * math.cos(q[1] + q[2])


@pytest.fixture(scope="module")
def ur5e():
    return kin.load_robot("ur5e")


def test_the_factors_are_the_ur5e_singularities(ur5e):
    factors = floor_factors(ur5e)
    assert sorted(f.kind for f in factors) == ["elbow", "shoulder", "wrist"]
    rng = np.random.default_rng(0)
    Q = rng.uniform(-math.pi, math.pi, (50, 6))
    sh = next(f for f in factors if f.kind == "shoulder")
    vals = np.asarray(sh(Q)).ravel()
    ref = np.array([shoulder(q) for q in Q])
    assert np.sign(vals).tolist() == np.sign(ref).tolist()            # the same factor up to a positive scale
    assert floor_factors(ur5e) is factors                               # looked up once per robot


def test_a_shoulder_sign_change_separates_and_the_straight_line_really_passes_sigma_zero(ur5e):
    start = np.radians([0, -90, 90, -90, -90, 0])
    goal = start.copy()
    goal[1] = math.radians(-170)            # the wrist centre swings over the base axis: the shoulder factor flips
    assert shoulder(start) * shoulder(goal) < 0
    assert math.sin(start[2]) * math.sin(goal[2]) > 0 and math.sin(start[4]) * math.sin(goal[4]) > 0
    sep = sign_separation(floor_factors(ur5e), start, goal)
    assert sep is not None and sep.kind == "sign" and sep.joints == (2, 3, 4) and "shoulder" in sep.reason
    # independent: σ_min along the straight line drops below any floor (numpy, fine steps)
    t = np.linspace(0, 1, 20001)
    assert min(sigma_numpy(start + s * (goal - start)) for s in t) < FLOOR
    # the planner answers with it, and OMPL's failure is not all it says
    res = plan(ur5e, start, goal, sigma_min=FLOOR, time_limit=0.2)
    assert not res.success and res.separation is not None and res.separation.kind == "sign"
    assert res.status.startswith("no joint path exists: the shoulder factor")


def test_no_floor_no_sign_verdict(ur5e):
    start = np.radians([0, -90, 90, -90, -30, 0])
    goal = np.radians([0, -90, 90, -90, 30, 0])
    cells = free_cells(ur5e.chain.lower, ur5e.chain.upper, None)
    assert Separator(cells, ur5e, None).separation(start, goal) is None          # without a floor σ = 0 is allowed
    sep = Separator(cells, ur5e, FLOOR).separation(start, goal)
    assert sep is not None and sep.joints == (5,) and "sin(q5)" in sep.reason
    res = plan(ur5e, start, goal, time_limit=0.5)                                  # no floor: the line is valid
    assert res.success


def test_a_numeric_analysis_proves_nothing_here():
    panda = kin.load_robot("franka_panda")
    assert floor_factors(panda) == ()


def test_a_goal_pose_under_the_floor_keeps_every_factor_sign(ur5e):
    start = np.radians([0, -90, 90, -90, -90, 0])
    pose = make_transform(rpy_to_matrix(np.zeros(3)), [0.45, -0.2, 0.2])
    res = plan(ur5e, start, goal_pose=pose, sigma_min=FLOOR, time_limit=2.0)
    assert res.success, res.status
    g = res.goal
    assert np.abs(ur5e.fk(g) - pose).max() < 1e-9
    assert math.sin(g[2]) * math.sin(start[2]) > 0 and math.sin(g[4]) * math.sin(start[4]) > 0
    assert shoulder(g) * shoulder(start) > 0
    assert np.all(np.abs(res.path[-1] - res.path[0]) <= 2 * math.pi)
