"""Planning on the 7-DOF arms (Panda, iiwa) around their point-set windows of margin 0.05 rad: every
motion the planner keeps is the one ``check_path`` proves, returned paths are proven and clear at
every densely interpolated state (membership by every distance in numpy), a σ_min floor is proven
too (numpy SVD of the numpy Jacobian of tests/dh_numpy.py), and the iiwa's elbow slab separates a
query at once.  ``rmt plan`` / ``rmt check-path`` say the windows are proven."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from planning.ompl.planner import default_range, plan
from planning.ompl.validity import JointSpaceChecker
from planning.validate import check_path
from studies.cli import main
from tests.dh_numpy import jacobian_numpy
from tests.planning.seven_dof import ROBOTS, inside_numpy, margin_windows, through_window

STEP = math.radians(0.1)


def dense(path: np.ndarray, step: float = STEP) -> np.ndarray:
    """States along a joint path, no joint moving more than ``step`` between two of them."""
    out = [path[:1]]
    for a, b in zip(path[:-1], path[1:]):
        k = max(int(np.ceil(np.abs(b - a).max() / step)), 1)
        out.append(a + np.linspace(0, 1, k + 1)[1:, None] * (b - a))
    return np.vstack(out)


def in_any_window(ws, Q: np.ndarray) -> np.ndarray:
    """(N,) inside some window: point-set windows by every distance (numpy), intervals by their ends."""
    inside = np.zeros(len(Q), bool)
    for w in ws.windows:
        if w.is_point_set:
            inside |= inside_numpy(w, Q)
        else:
            for lo, hi in w.intervals:
                inside |= (Q[:, w.joint] >= lo) & (Q[:, w.joint] <= hi)
    return inside


def sigma_numpy(chain, Q: np.ndarray) -> np.ndarray:
    return np.array([np.linalg.svd(jacobian_numpy(chain, q), compute_uv=False).min() for q in Q])


@pytest.mark.parametrize("name", ROBOTS)
def test_the_planners_motion_check_is_check_paths_proof(name):
    """For every motion: kept by the planner exactly when check_path proves it valid."""
    robot, ws = margin_windows(name)
    checker = JointSpaceChecker(robot, ws)
    rng = np.random.default_rng(4)
    Q = robot.random_configurations(600, seed=12)
    A = Q[:300]
    D = rng.normal(size=A.shape)
    D *= rng.uniform(0.05, default_range(robot), (len(A), 1)) / np.linalg.norm(D, axis=1, keepdims=True)
    B = np.clip(A + D, robot.chain.lower, robot.chain.upper)
    pairs = list(zip(A, B))
    for w in [w for w in ws.windows if w.is_point_set]:
        pairs += [through_window(robot, w, rng) for _ in range(15)]
        for a in A[:15]:                                 # ending near a point: crossing or grazing
            b = a.copy()
            b[[j - 1 for j in w.joints]] = w.points[rng.integers(len(w.points))] + rng.normal(0, 0.04, len(w.joints))
            pairs.append((a, np.clip(b, robot.chain.lower, robot.chain.upper)))
    kept = refused = 0
    for a, b in pairs:
        chk = check_path(robot, np.array([a, b]), ws, dense=False)
        proven_valid = chk.valid and chk.windows_check == "proven"
        assert checker.motion_valid(list(a), list(b)) == proven_valid
        kept += proven_valid
        refused += not proven_valid
    assert kept >= 50 and refused >= 50


@pytest.mark.parametrize("name", ROBOTS)
def test_plans_around_the_windows_are_proven_and_clear(name):
    robot, ws = margin_windows(name)
    rng = np.random.default_rng(21)
    point_sets = [w for w in ws.windows if w.is_point_set]
    planned = 0
    for k in range(8):
        start, goal = through_window(robot, point_sets[k % len(point_sets)], rng, windows=ws)
        assert in_any_window(ws, dense(np.array([start, goal]))).any()       # the straight line is blocked
        res = plan(robot, start, goal, ws, seed=k, time_limit=5.0)
        if res.separation is not None:                  # the iiwa's elbow slab between them: said at once
            assert res.separation.kind == "slab" and res.separation.joints == (4,)
            assert (start[3] > 0) != (goal[3] > 0)
            continue
        assert res.success and res.proven, res.attempts
        assert all(res.proof.methods[w.name] == "distance" for w in point_sets)
        P = dense(res.path)
        assert np.allclose(res.path[0], start) and np.allclose(res.path[-1], goal)
        assert not in_any_window(ws, P).any()
        assert np.all((P >= robot.chain.lower - 1e-12) & (P <= robot.chain.upper + 1e-12))
        chk = check_path(robot, res.path, ws)
        assert chk.valid and chk.windows_check == "proven"
        planned += 1
    assert planned >= 4


def test_the_iiwa_elbow_slab_separates_at_once():
    robot, ws = margin_windows("kuka_iiwa14")
    start = np.array([0.3, 0.5, 0.2, 1.0, 0.4, 0.8, 0.1])
    goal = np.array([-0.3, 0.6, -0.2, -1.0, 0.5, 0.7, 0.2])
    assert not in_any_window(ws, np.array([start, goal])).any()
    res = plan(robot, start, goal, ws, seed=0)
    assert not res.success and res.separation.kind == "slab" and res.separation.joints == (4,)
    assert res.status.startswith("no joint path exists: the elbow window q4 ∈ [-2.865°, 2.865°] separates")
    assert res.attempts == [res.status]                 # answered before any planning


def test_a_sigma_floor_on_the_panda_is_proven():
    robot, ws = margin_windows("franka_panda")
    floor = 0.01                       # σ_min is low near the Panda's singular set: 0.011 (median) 0.4 rad away
    rng = np.random.default_rng(3)
    done = 0
    for _ in range(200):
        start, goal = through_window(robot, ws.windows[done % len(ws.windows)], rng, windows=ws)
        if sigma_numpy(robot.chain, np.array([start, goal])).min() < 2 * floor:
            continue
        res = plan(robot, start, goal, ws, sigma_min=floor, seed=done, time_limit=5.0)
        assert res.success and res.proven and res.check.sigma_check == "proven", res.attempts
        P = dense(res.path, math.radians(0.5))
        assert sigma_numpy(robot.chain, P).min() >= floor and not in_any_window(ws, P).any()
        done += 1
        if done == 3:
            break
    assert done == 3


def _cli(argv, capsys):
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def test_cli_plan_and_check_path_say_the_windows_are_proven(capsys, tmp_path):
    """The Panda's file is in rad: --margin 0.05 gives the windows above; the straight line between
    start and goal crosses the 5-joint window (numpy check), the plan goes around it."""
    robot, ws = margin_windows("franka_panda")
    start = [2.88, -0.12, -0.3, -2.22, -1.79, 3.03, -0.77]
    goal = [2.87, 0.12, -0.48, -2.09, -1.53, 3.68, -0.56]
    assert in_any_window(ws, dense(np.array([start, goal]))).any()
    out_csv = tmp_path / "panda.csv"
    args = ["plan", "franka_panda", "--start", *map(str, start), "--goal", *map(str, goal), "--margin", "0.05"]
    rc, out, err = _cli([*args, "--out", str(out_csv), "--json"], capsys)
    d = json.loads(out)
    assert rc == 0 and d["success"] and d["proven"] and d["checks"]["windows"] == "proven"
    # the robot's default σ_min floor is proven too (issue 29, finding 3), so no note about sampled windows
    assert d["checks"]["sigma_min"] == "proven" and d["sigma_floor"]["source"] == "rule" and err == ""
    rc, out, err = _cli([*args, "--no-singularity-check", "--json"], capsys)
    assert rc == 0 and "drop --no-singularity-check" in err     # the windows hold the set as far as their samples
    rc, out, err = _cli(["check-path", "franka_panda", str(out_csv), "--margin", "0.05"], capsys)
    assert rc == 0 and "windows of ±0.05 rad (--margin 0.05, robot file unit rad) proven" in out
    P = np.loadtxt(out_csv, delimiter=",", skiprows=1)
    assert not in_any_window(ws, dense(P)).any()
    rc, out, err = _cli([*args, "--sigma-floor", "0.05", "--json"], capsys)
    d = json.loads(out)
    assert rc == 0 and d["proven"] and d["checks"] == {"windows": "proven", "sigma_min": "proven", "collisions": None}
    assert err == ""                                    # with a floor proven, no note
    assert sigma_numpy(robot.chain, dense(np.array(d["path"]), math.radians(0.5))).min() >= 0.05
