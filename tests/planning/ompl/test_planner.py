"""OMPL joint-space planning around singular windows (planning.ompl.planner) and ``rmt plan`` /
``rmt check-path``.

Planned paths are re-validated here without the planning layer: the path is interpolated by this
file's own rule (no joint moves more than 0.1° between states) and every state is tested against the
windows' defining geometry — for the FANUC M-16iB/20 the wrist window |q5| ≤ w, the elbow window
|q3 − (atan2(0.74, 0.1) + kπ)| ≤ w and the shoulder window ρ ≤ ε, ρ being the distance of the wrist
centre from the joint-1 axis computed with the plain numpy DH of ``tests/dh_numpy.py``; σ_min with
numpy's SVD of the numpy Jacobian; tool poses and tool points with the numpy FK.

Geometry to keep in mind: every single-joint window is a slab across the whole joint space, so a
start and goal on opposite sides of one are not connectable; the FANUC pair used below is on the
same side of every slab and its straight line crosses the (curved) shoulder window.
"""
from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest
from scipy.optimize import brentq

import kin
from planning.errors import PlanningError
from planning.ompl.planner import plan
from planning.ompl.validity import KeepOutBox
from planning.validate import check_path
from planning.windows import build_windows
from studies.cli import main
from tests.dh_numpy import fk_numpy, frames_numpy, jacobian_numpy

MARGIN = 0.05
STEP = math.radians(0.1)
ELBOW_ROOT = math.atan2(0.74, 0.1)     # FANUC elbow factor 0.1 sin q3 − 0.74 cos q3 = 0
# FANUC: same side of the wrist and elbow slabs, straight line through the shoulder window
START = np.array([-0.01, 0.49, 4.4, -2.23, 0.51, -0.91])
GOAL = np.array([-1.92, 1.08, 1.7, -1.37, 2.03, -1.63])
# FANUC: a free straight line (easy problem)
EASY_A = np.array([0.2, 0.3, 0.2, 0.1, 0.6, 0.1])
EASY_B = np.array([0.5, 0.1, 0.4, -0.2, 0.9, 0.3])


@pytest.fixture(scope="module")
def fanuc():
    robot = kin.load_robot("fanuc_m16ib20")
    return robot, build_windows(robot, margin=MARGIN)


@pytest.fixture(scope="module")
def scara():
    robot = kin.load_robot("scara_rrp")
    return robot, build_windows(robot, margin=MARGIN)


# ---- independent helpers -------------------------------------------------------------------
def dense(path: np.ndarray, step: float = STEP) -> np.ndarray:
    """States along a joint path, no joint moving more than ``step`` between two of them."""
    out = [path[:1]]
    for a, b in zip(path[:-1], path[1:]):
        k = max(1, math.ceil(np.abs(b - a).max() / step))
        t = np.arange(1, k + 1)[:, None] / k
        out.append(a + t * (b - a))
    return np.vstack(out)


def wrist_radius(chain, q) -> float:
    """Distance of the FANUC wrist centre (origin of frame 4) from the joint-1 axis, numpy DH."""
    F = frames_numpy(chain, q)
    p = np.linalg.solve(F[0], F[4][:, 3])[:3]
    return math.hypot(p[0], p[1])


def fanuc_outside_windows(chain, ws, Q: np.ndarray) -> np.ndarray:
    """(N,) True where a FANUC state is outside all three windows, from their geometry."""
    eps = next(w.epsilon for w in ws.windows if w.name.startswith("shoulder"))
    elbow = np.array([ELBOW_ROOT + k * math.pi for k in (-1, 0, 1)])
    ok_wrist = np.abs(Q[:, 4]) > MARGIN
    ok_elbow = np.abs(Q[:, 2][:, None] - elbow[None]).min(axis=1) > MARGIN
    ok_shoulder = np.array([wrist_radius(chain, q) > eps for q in Q])
    return ok_wrist & ok_elbow & ok_shoulder


def within_limits(chain, Q: np.ndarray) -> bool:
    return bool(np.all((Q >= chain.lower - 1e-12) & (Q <= chain.upper + 1e-12)))


def sigma_numpy(chain, Q: np.ndarray) -> np.ndarray:
    return np.array([np.linalg.svd(jacobian_numpy(chain, q), compute_uv=False).min() for q in Q])


# ---- planned paths pass dense validation -----------------------------------------------------
def test_shoulder_window_is_the_wrist_radius(fanuc):
    """The independent shoulder test used below is the window's own factor (|g| = ρ)."""
    robot, ws = fanuc
    sh = next(w for w in ws.windows if w.name.startswith("shoulder"))
    Q = robot.random_configurations(20, seed=3)
    np.testing.assert_allclose(np.abs(sh.g(Q)), [wrist_radius(robot.chain, q) for q in Q], atol=1e-12)


def test_fanuc_path_around_the_shoulder_window(fanuc):
    robot, ws = fanuc
    chain = robot.chain
    straight = dense(np.array([START, GOAL]))
    assert fanuc_outside_windows(chain, ws, straight[[0, -1]]).all()
    assert not fanuc_outside_windows(chain, ws, straight).all()          # the straight line is blocked
    res = plan(robot, START, GOAL, ws, time_limit=2.0, seed=1)
    assert res.success and not res.straight_line_valid
    np.testing.assert_array_equal(res.path[0], START)
    np.testing.assert_array_equal(res.path[-1], GOAL)
    Q = dense(res.path)
    assert within_limits(chain, Q)
    assert fanuc_outside_windows(chain, ws, Q).all()
    assert check_path(robot, res.path, ws).valid
    assert math.isclose(res.length, float(np.linalg.norm(np.diff(res.path, axis=0), axis=1).sum()), rel_tol=1e-12)
    assert res.length > np.linalg.norm(GOAL - START)


def test_scara_path_stays_on_its_side_of_the_boundary_slab(scara):
    robot, ws = scara
    a, b = np.array([-1.0, 0.8, -0.2]), np.array([1.5, 2.0, -0.15])
    res = plan(robot, a, b, ws, time_limit=1.0, seed=0)
    assert res.success
    Q = dense(res.path)
    assert within_limits(robot.chain, Q)
    assert (np.abs(Q[:, 1]) > MARGIN).all()          # boundary singularity sin q2 = 0 at q2 = 0 only
    assert check_path(robot, res.path, ws).valid


def test_scara_opposite_sides_of_a_slab_are_not_connectable(scara):
    robot, ws = scara
    res = plan(robot, [0.3, -0.8, -0.2], [0.3, 0.8, -0.2], ws, time_limit=0.2, seed=0)
    assert not res.success and len(res.path) == 0 and not res.straight_line_valid


def test_sigma_floor_without_windows(fanuc):
    robot, _ = fanuc
    floor = 0.04
    s_ends = sigma_numpy(robot.chain, np.array([START, GOAL]))
    assert (s_ends > floor).all()
    assert sigma_numpy(robot.chain, dense(np.array([START, GOAL]), math.radians(0.5))).min() < floor
    res = plan(robot, START, GOAL, None, sigma_min=floor, time_limit=2.0, seed=0)
    assert res.success and not res.straight_line_valid
    assert sigma_numpy(robot.chain, dense(res.path)).min() >= floor
    assert res.min_sigma >= floor
    assert check_path(robot, res.path, None, sigma_min=floor).valid


# ---- invalid requests ----------------------------------------------------------------------
def _shoulder_singular_q() -> np.ndarray:
    """A FANUC configuration with the wrist centre on the joint-1 axis (q3 = 0, ρ(q2) = 0)."""
    chain = kin.load_chain("fanuc_m16ib20")

    def signed(q2):   # the wrist centre's x in the arm plane (q1 = 0), numpy DH
        F = frames_numpy(chain, np.array([0.0, q2, 0.0, 0.0, 0.5, 0.0]))
        return np.linalg.solve(F[0], F[4][:, 3])[0]

    q2 = brentq(signed, 1.5, 2.79)
    return np.array([0.0, q2, 0.0, 0.0, 0.5, 0.0])


@pytest.mark.parametrize("which, change, pattern", [
    ("start", (4, 0.01), r"start configuration is invalid: joint 5 \(J5\) = 0\.01 rad is inside the singular window "
                         r"'wrist[^']*' \[-0\.05 rad, 0\.05 rad\]"),
    ("goal", (2, ELBOW_ROOT), r"goal configuration is invalid: joint 3 \(J3\) = 1\.43\d* rad is inside the singular "
                              r"window 'elbow"),
    ("start", (0, 3.5), r"start configuration is invalid: joint 1 \(J1\) = 3\.5 rad is outside its limits "
                        r"\[-2\.97 rad, 2\.97 rad\]"),
    ("goal", (5, -8.0), r"goal configuration is invalid: joint 6 \(J6\) = -8 rad is outside its limits"),
])
def test_invalid_start_or_goal_names_the_joint(fanuc, which, change, pattern):
    robot, ws = fanuc
    a, b = EASY_A.copy(), EASY_B.copy()
    q = a if which == "start" else b
    q[change[0]] = change[1]
    with pytest.raises(PlanningError, match=pattern):
        plan(robot, a, b, ws, time_limit=0.5)


def test_start_in_the_shoulder_window_and_below_the_floor(fanuc):
    robot, ws = fanuc
    q = _shoulder_singular_q()
    assert wrist_radius(robot.chain, q) < 1e-9
    with pytest.raises(PlanningError, match=r"start configuration is invalid: inside the singular window 'shoulder"):
        plan(robot, q, EASY_B, ws, time_limit=0.5)
    s = sigma_numpy(robot.chain, EASY_A[None])[0]
    msg = rf"start configuration is invalid: σ_min = {s:.3g} \(SI\) is below the floor 10 \(SI\)"
    with pytest.raises(PlanningError, match=msg):
        plan(robot, EASY_A, EASY_B, ws, sigma_min=10.0, time_limit=0.5)


def test_request_errors(fanuc):
    robot, ws = fanuc
    with pytest.raises(PlanningError, match="exactly one of goal"):
        plan(robot, EASY_A, None, ws)
    with pytest.raises(PlanningError, match="objective 'fast' unknown; allowed: none, length, singularity"):
        plan(robot, EASY_A, EASY_B, ws, objective="fast")


# ---- reproducibility -----------------------------------------------------------------------
def test_same_seed_same_plan_different_seeds_differ(fanuc):
    robot, ws = fanuc
    paths = [plan(robot, START, GOAL, ws, time_limit=2.0, seed=s).path for s in (5, 5, 6, 7, 8)]
    assert paths[0].shape[0] > 2
    assert np.array_equal(paths[0], paths[1])
    assert any(p.shape != paths[0].shape or not np.array_equal(p, paths[0]) for p in paths[2:])


# ---- planner names -------------------------------------------------------------------------
@pytest.mark.parametrize("name, cls", [("RRTConnect", "RRTConnect"), ("RRT*", "RRTstar"), ("PRM*", "PRMstar"),
                                       ("BIT*", "BITstar"), ("rrt", "RRT")])
def test_planner_names(fanuc, name, cls):
    robot, ws = fanuc
    res = plan(robot, EASY_A, EASY_B, ws, planner=name, time_limit=0.3, seed=0)
    assert res.planner == cls
    assert res.success and check_path(robot, res.path, ws).valid


def test_unknown_planner_lists_the_allowed_ones(fanuc):
    robot, ws = fanuc
    with pytest.raises(PlanningError) as e:
        plan(robot, EASY_A, EASY_B, ws, planner="Dijkstra")
    msg = str(e.value)
    assert "'Dijkstra' unknown" in msg
    for name in ("RRTConnect", "RRTstar", "PRMstar", "BITstar", "RRT*"):
        assert name in msg


# ---- goal pose -----------------------------------------------------------------------------
def test_goal_pose_ends_at_that_pose(fanuc):
    robot, ws = fanuc
    pose = fk_numpy(robot.chain, EASY_B)
    res = plan(robot, EASY_A, goal_pose=pose, windows=ws, time_limit=1.0, seed=0)
    assert res.success
    T = fk_numpy(robot.chain, res.path[-1])
    np.testing.assert_allclose(T[:3, 3], pose[:3, 3], atol=1e-6)
    np.testing.assert_allclose(T[:3, :3], pose[:3, :3], atol=1e-6)
    assert fanuc_outside_windows(robot.chain, ws, dense(res.path)).all()


# ---- keep-out box --------------------------------------------------------------------------
def test_keep_out_box_makes_the_path_go_around(fanuc):
    robot, ws = fanuc
    chain = robot.chain
    a = np.array([0.8, 0.1, 0.2, 0.3, 0.9, 0.0])
    b = np.array([-0.8, 0.3, 0.1, -0.2, 1.1, 0.4])
    p_mid = fk_numpy(chain, 0.5 * (a + b))[:3, 3]
    box = KeepOutBox(tuple(p_mid - 0.05), tuple(p_mid + 0.05))

    def inside(Q):
        P = np.array([fk_numpy(chain, q)[:3, 3] for q in Q])
        return np.all((P >= p_mid - 0.05) & (P <= p_mid + 0.05), axis=1)

    assert not inside(np.array([a, b])).any()
    assert inside(dense(np.array([a, b]))).any()
    res = plan(robot, a, b, ws, boxes=(box,), time_limit=2.0, seed=0)
    assert res.success and not res.straight_line_valid
    assert not inside(dense(res.path)).any()
    assert fanuc_outside_windows(chain, ws, dense(res.path)).all()


# ---- CLI -----------------------------------------------------------------------------------
def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


PUMA_START = [0, -45, 180, 0, 45, 0]          # degrees (puma560 file units)
PUMA_GOAL = [60, -30, 150, 30, 60, 45]


@pytest.fixture(scope="module")
def puma_windows():
    robot = kin.load_robot("puma560")
    return robot, build_windows(robot, margin=math.radians(3))


def test_cli_plan_json_in_file_units(capsys, puma_windows, tmp_path):
    robot, ws = puma_windows
    out_csv = tmp_path / "path.csv"
    code, out, err = run(capsys, "plan", "puma560", "--start", *map(str, PUMA_START), "--goal",
                         *map(str, PUMA_GOAL), "--margin", "3", "--json", "--out", str(out_csv))
    assert code == 0, err
    d = json.loads(out)
    assert {"success", "path", "planner", "time_s", "length", "min_sigma", "windows"} <= set(d)
    assert d["success"] is True and d["planner"] == "RRTConnect" and d["time_s"] > 0
    P = np.array(d["path"])
    np.testing.assert_allclose(P[0], PUMA_START, atol=1e-9)      # degrees, not radians
    np.testing.assert_allclose(P[-1], PUMA_GOAL, atol=1e-9)
    P_si = np.radians(P)
    assert math.isclose(d["length"], float(np.linalg.norm(np.diff(P_si, axis=0), axis=1).sum()), rel_tol=1e-9)
    chk = check_path(robot, P_si, ws)
    assert chk.valid and math.isclose(d["min_sigma"], chk.min_sigma, rel_tol=1e-6)
    assert [n.split(":")[0] for n in d["windows"]] == ["wrist", "elbow", "shoulder"]
    with open(out_csv, newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0] == [f"q{i}" for i in range(1, 7)]
    np.testing.assert_allclose(np.array(rows[1:], float), P, atol=1e-9)
    code, out, _ = run(capsys, "check-path", "puma560", str(out_csv), "--margin", "3", "--json")
    assert code == 0 and json.loads(out)["valid"] is True


def test_cli_check_path_exit_codes(capsys, tmp_path):
    bad_path = tmp_path / "cross.csv"
    bad_path.write_text("q1,q2,q3,q4,q5,q6\n0,-45,180,0,30,0\n0,-45,180,0,20,0\n0,-45,180,0,-30,0\n")
    code, out, _ = run(capsys, "check-path", "puma560", str(bad_path), "--margin", "3", "--json")
    assert code == 1
    d = json.loads(out)
    assert d["valid"] is False and d["first_violation"]["index"] == 1 and d["first_violation"]["kind"] == "window"
    # no windows: the robot's default σ_min floor flags the wrist singularity q5 = 0 the path crosses
    # (issue 29, finding 3); with the floor off too the path is valid
    code, out, _ = run(capsys, "check-path", "puma560", str(bad_path), "--json")
    assert code == 1 and json.loads(out)["first_violation"]["kind"] == "sigma_min"
    code, _, _ = run(capsys, "check-path", "puma560", str(bad_path), "--no-singularity-check")
    assert code == 0
    broken = tmp_path / "broken.csv"
    broken.write_text("0,-45,180,0,30,0\n0,-45,abc,0,30,0\n")
    code, out, err = run(capsys, "check-path", "puma560", str(broken))
    assert code == 2 and out == ""
    assert err.startswith("rmt: error:") and err.count("\n") == 1 and "line 2" in err
    code, _, err = run(capsys, "check-path", "puma560", str(tmp_path / "missing.csv"))
    assert code == 2 and "no such joint-path file" in err


# ---- impossible queries, pose goals across the wrist window, proofs ----------------------------------
def test_separated_query_is_answered_before_planning():
    robot = kin.load_robot("fanuc_m16ib20")
    ws = build_windows(robot, margin=0.05)
    start = np.array([0.0, -0.3, 0.4, 0.2, -0.6, 0.0])
    goal = np.array([0.4, -0.2, 0.3, -0.2, 0.8, 0.1])
    res = plan(robot, start, goal, ws, time_limit=30.0, seed=0)
    assert not res.success and res.separation is not None
    assert res.status.startswith("no joint path exists: the wrist window q5 ∈ [-0.05 rad, 0.05 rad] separates "
                                 "start (q5 = -0.6 rad) and goal (q5 = 0.8 rad)")
    assert res.attempts == [res.status]                  # OMPL never ran
    assert res.to_dict()["separation"]["joints"] == [5]


def test_returned_paths_are_proven():
    robot = kin.load_robot("fanuc_m16ib20")
    ws = build_windows(robot, margin=0.05)
    res = plan(robot, np.array([0.0, -0.8, 0.7, 0.3, 0.8, 0.0]), np.array([0.5, -0.5, -1.6, -0.3, 0.9, 0.4]), ws,
               time_limit=2.0, seed=0)
    assert res.success and res.proven and res.proof.methods["wrist: sin(q5)"] == "exact"
    assert any(m == "interval" for m in res.proof.methods.values())


# ---- the PRM family with the singularity objective (it used to deadlock) -----------------------
def test_edge_costs_are_the_trapezoid_rule_with_numpy_sigma(fanuc):
    """Length + ∫ 0.01/σ_min ds per motion, against a loop with numpy's SVD of the numpy Jacobian."""
    from planning.ompl.planner import _edge_costs
    robot, _ = fanuc
    A = robot.random_configurations(4, seed=1)
    B = robot.random_configurations(4, seed=2)
    got = _edge_costs(robot, A, B, 0.1, 0.01)
    for a, b, g in zip(A, B, got):
        L = float(np.linalg.norm(b - a))
        k = max(1, math.ceil(L / 0.1))
        c = 0.01 / sigma_numpy(robot.chain, np.array([a + t * (b - a) for t in np.linspace(0, 1, k + 1)]))
        assert g == pytest.approx(L + 0.5 * (c[:-1] + c[1:]).sum() * L / k, rel=1e-9)


@pytest.mark.parametrize("planner", ["PRM*", "PRM"])
def test_prm_with_singularity_objective_returns(planner, fanuc):
    """OMPL's PRM searches its roadmap in a second thread; a Python objective there waited for the
    GIL forever.  Run in a subprocess so a regression fails this test instead of hanging the suite."""
    import subprocess
    import sys
    code = ("import json, numpy as np, kin\n"
            "from planning.windows import build_windows\nfrom planning.ompl.planner import plan\n"
            "r = kin.load_robot('fanuc_m16ib20')\nws = build_windows(r, margin=0.05)\n"
            f"res = plan(r, np.array({START.tolist()}), np.array({GOAL.tolist()}), ws, planner='{planner}', "
            "objective='singularity', time_limit=0.5, seed=1)\n"
            "print(json.dumps({'success': res.success, 'path': res.path.tolist(), 'status': res.status}))\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                       cwd=str(__import__("pathlib").Path(__file__).resolve().parents[3]))
    assert p.returncode == 0, p.stderr[-2000:]
    d = json.loads(p.stdout.strip().splitlines()[-1])
    assert d["success"] and "minimised on the roadmap" in d["status"]
    robot, ws = fanuc
    Q = dense(np.array(d["path"]))
    assert within_limits(robot.chain, Q) and fanuc_outside_windows(robot.chain, ws, Q[::20]).all()


def test_invalid_start_in_degrees_names_the_joint_window_and_unit():
    """ur5e (a robot file in degrees, 5° windows): the message speaks degrees, as the user wrote them."""
    robot = kin.load_robot("ur5e")
    ws = build_windows(robot, margin=math.radians(5))
    with pytest.raises(PlanningError) as e:
        plan(robot, np.radians([0, -90, 90, -90, 0, 0]), np.radians([0, -90, 90, -90, -90, 0]), ws, time_limit=0.2)
    assert str(e.value) == ("start configuration is invalid: joint 5 (wrist2) = 0° is inside the singular window "
                            "'wrist: sin(q5)' [-5°, 5°]")
    with pytest.raises(PlanningError, match=r"goal configuration is invalid: joint 3 \(elbow\) = 361° is outside its "
                                            r"limits \[-360°, 360°\]"):
        plan(robot, np.radians([0, -90, 90, -90, -90, 0]), np.radians([0, -90, 361, -90, -90, 0]), ws, time_limit=0.2)
